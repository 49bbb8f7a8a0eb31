#!/usr/bin/env bash
# Installs the Debian 12 packages visopt needs, only those not yet installed (a second run
# costs nothing). Needs root (or sudo).
set -euo pipefail
PACKAGES=(
  build-essential cmake ninja-build pkgconf git ca-certificates
  libtbb-dev libglm-dev nlohmann-json3-dev libpng-dev zlib1g-dev libcli11-dev
  libvtk9-dev libvtkgdcm-dev libopenvdb-dev libboost-iostreams-dev libopenmesh-dev
  liblz4-dev libzstd-dev libgtest-dev libbenchmark-dev
  qt6-base-dev xvfb xauth clang-format
  libopenmpi-dev openmpi-bin
  clang libclang-rt-14-dev
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  [[ $(id -u) -eq 0 ]] || SUDO="sudo"
  echo "visopt: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi
