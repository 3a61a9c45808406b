#!/usr/bin/env bash
# Install what so3fft needs on Debian/Ubuntu beyond the Rust toolchain:
# FFTW 3 (with its threads library), CMake, pkg-config and valgrind (for the C test suite),
# Open MPI (for the distributed plans' checks under mpirun), and Python's venv module (the
# Python package is built and tested in a virtual environment).
set -euo pipefail
pkgs=(libfftw3-dev cmake pkg-config valgrind gcc g++ make libopenmpi-dev openmpi-bin)
# A python3 without a working venv module (Debian's, before python3-venv is installed).
if ! python3 -m venv --help >/dev/null 2>&1 || ! python3 -c 'import ensurepip' >/dev/null 2>&1; then
  pkgs+=(python3-venv)
fi
missing=()
for p in "${pkgs[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
