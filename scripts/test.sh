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
  cargo build --release --features mpi --lib --example mpi_check
  # The C API of include/so3fft_mpi.h against the library built with the feature.
  mpilib=target/mpi-lib
  mkdir -p "$mpilib"
  cp target/release/libso3fft.so "$mpilib/"
  ln -sf libso3fft.so "$mpilib/libso3fft.so.0"
  mpicc -std=c11 -Wall -Wextra -Werror -Iinclude -o "$mpilib/test_mpi" c_tests/mpi/test_mpi.c \
    -L"$mpilib" -lso3fft -Wl,-rpath,"$PWD/$mpilib" -lm
  for np in 1 2 3 4; do
    # A deadlock fails the run instead of hanging it.
    timeout 600 mpirun --allow-run-as-root --oversubscribe -np "$np" \
      target/release/examples/mpi_check
    timeout 300 mpirun --allow-run-as-root --oversubscribe -np "$np" "$mpilib/test_mpi"
  done
else
  echo "mpirun or mpicc not found: distributed plans not tested" >&2
  exit 1
fi
