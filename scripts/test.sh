#!/usr/bin/env bash
# Every test: the Rust suite (unit, integration, doc tests), the C/C++ suite under CTest
# (C API, SOFT compatibility layer, installed-package tests, valgrind runs), and the
# distributed plans under mpirun on 1..4 ranks (feature `mpi`).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cargo test --release
if [ -f CMakeLists.txt ]; then
  cmake -S . -B build/ci -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build/ci -j2
  ctest --test-dir build/ci --output-on-failure
fi
if command -v mpirun >/dev/null && command -v mpicc >/dev/null; then
  cargo build --release --features mpi --example mpi_check
  for np in 1 2 3 4; do
    # A deadlock fails the run instead of hanging it.
    timeout 600 mpirun --allow-run-as-root --oversubscribe -np "$np" \
      target/release/examples/mpi_check
  done
else
  echo "mpirun or mpicc not found: distributed plans not tested" >&2
  exit 1
fi
