#!/usr/bin/env bash
# The main job: SO(3) FFT round trips at a few bandwidths, with time per stage and error.
# Usage: scripts/demo.sh [B1,B2,...]   (default 8,16,32,64,128)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cargo run --release --quiet --example demo -- "$@"
