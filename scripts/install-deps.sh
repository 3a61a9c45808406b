#!/usr/bin/env bash
# Install what so3fft needs on Debian/Ubuntu beyond the Rust toolchain:
# FFTW 3 (with its threads library), CMake, pkg-config and valgrind (for the C test suite),
# Open MPI (for the distributed plans' checks under mpirun).
set -euo pipefail
pkgs=(libfftw3-dev cmake pkg-config valgrind gcc g++ make libopenmpi-dev openmpi-bin)
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
