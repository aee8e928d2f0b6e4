#!/usr/bin/env bash
# Installs every Debian package Canopy's build, tests and benchmarks need.
# Idempotent: only missing packages are installed, and `apt-get update` runs
# at most once, only when something is missing. Must run as root (or via sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config clang-format python3
  pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers clinfo
  libembree-dev
  libopenimageio-dev openimageio-tools libopenexr-dev libpng-dev
  libtinyobjloader-dev libassimp-dev zlib1g-dev nlohmann-json3-dev libcli11-dev libfmt-dev libtbb-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  slurm-wlm munge
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

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
