#!/usr/bin/env bash
# Every test: the Rust suite (unit, integration, doc tests) and the C/C++ suite under CTest
# (C API, SOFT compatibility layer, installed-package tests, valgrind runs).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cargo test --release
if [ -f CMakeLists.txt ]; then
  cmake -S . -B build/ci -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build/ci -j2
  ctest --test-dir build/ci --output-on-failure
fi
