#!/usr/bin/env bash
# Fails when the committed C header include/so3fft.h differs from the one cbindgen generates
# from src/capi/ (build.rs). Used by CI (.ci/run).
#
# 1. build.rs in check mode (SO3FFT_CHECK_HEADER=1): it never writes the header and fails
#    the build when include/so3fft.h differs from the generated header.
# 2. A normal build (cargo build/test/clippy without SO3FFT_CHECK_HEADER=1) rewrites a stale
#    header silently, so also compare the working tree with the committed version.
# To update the header: build normally (cargo build), then commit include/so3fft.h.
set -euo pipefail
cd "$(dirname "$0")/.."

SO3FFT_CHECK_HEADER=1 cargo build --release --lib --quiet
echo "check-header: include/so3fft.h matches the header generated from src/capi/"

if git rev-parse --is-inside-work-tree >/dev/null 2>&1 &&
   git ls-files --error-unmatch include/so3fft.h >/dev/null 2>&1; then
  if ! git diff --exit-code HEAD -- include/so3fft.h; then
    echo "check-header: include/so3fft.h was regenerated and differs from the committed" \
         "version: commit the new header" >&2
    exit 1
  fi
  echo "check-header: include/so3fft.h is committed and up to date"
fi
