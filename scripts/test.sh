#!/usr/bin/env bash
# Every test: the Rust suite (unit, integration, doc tests; the library and the tools), the C/C++ suite under CTest
# (C API, SOFT compatibility layer, installed-package tests, valgrind runs, and the
# distributed plans under mpirun on 1..4 ranks: label `mpi`), the Rust MPI test
# (tests/mpi.rs, feature `mpi`), and the Python package (installed as a user would, into
# the virtual environment target/pyenv, then pytest and the example).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
if ! command -v mpirun >/dev/null || ! command -v mpicc >/dev/null; then
  echo "mpirun or mpicc not found: distributed plans cannot be tested" \
       "(scripts/install-deps.sh installs Open MPI)" >&2
  exit 1
fi
cargo test --release --workspace
if [ -f CMakeLists.txt ]; then
  # SO3FFT_MPI=ON adds libso3fft_mpi and its tests to every other C test; libso3fft is the
  # same with or without MPI (cargo test's target/release).
  cmake -S . -B build/ci -DCMAKE_BUILD_TYPE=Release -DSO3FFT_MPI=ON >/dev/null
  cmake --build build/ci -j2
  ctest --test-dir build/ci --output-on-failure
  # The default configuration (no MPI) too: C API and installed package.
  cmake -S . -B build/ci-nompi -DCMAKE_BUILD_TYPE=Release -DSO3FFT_VALGRIND_TESTS=OFF \
        -DSO3FFT_ATTACK_TESTS=OFF >/dev/null
  cmake --build build/ci-nompi -j2
  ctest --test-dir build/ci-nompi -L '^(c|downstream)$' --output-on-failure
fi
# The Rust crate with its feature `mpi` (MpiExchange), in its own target directory: cargo keeps
# one libso3fft per target directory whatever the features.
CARGO_TARGET_DIR=target/mpi cargo test --release --features mpi --test mpi
# The Python package, installed the way the README says, with its test dependencies.
python3 -m venv target/pyenv
target/pyenv/bin/pip install -q numpy "scipy>=1.15" pytest ducc0 matplotlib mypy
target/pyenv/bin/pip install -q ./python
target/pyenv/bin/pytest -q python/tests
# The package's annotations and the extension's stubs agree with its code.
target/pyenv/bin/mypy --ignore-missing-imports python/so3fft
target/pyenv/bin/python python/examples/match_rotation.py --out target/match_rotation.png
