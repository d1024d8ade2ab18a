#!/usr/bin/env bash
# Installs the Debian 12 packages ccsrm needs, only those that are missing.
# Idempotent: on a machine that has everything it prints one line and exits 0.
# gnuplot-nox draws the reports' figures (in DejaVu Sans); chromium renders
# them headless for the report screenshot test, which skips without it.
# python3-dev and python3-pybind11 build the Python module (python/), whose
# tests and examples use python3-pytest, -numpy, -h5py and -matplotlib.
# libopenmpi-dev and openmpi-bin run identification over MPI (docs/cluster.md);
# without them everything runs on threads and the MPI tests skip.
set -euo pipefail

packages=(
  build-essential cmake pkg-config clang
  libeigen3-dev libceres-dev libsuitesparse-dev libopencv-dev libhdf5-dev libgsl-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev gnuplot-nox fonts-dejavu-core
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-h5py python3-numpy python3-dev python3-pybind11 python3-pytest python3-matplotlib
  chromium
  libopenmpi-dev openmpi-bin
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
