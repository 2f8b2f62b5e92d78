#!/usr/bin/env bash
# Installs the Debian packages dcg-rig needs, only those that are missing.
# Idempotent: when everything is present it prints nothing and returns at once.
# Run as root (or with sudo available). PyPI is not used: Python packages come from apt.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build ccache
  libcgal-dev libembree-dev libeigen3-dev libtbb-dev libgmp-dev libmpfr-dev libboost-dev
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
  libgtest-dev libbenchmark-dev
  blender python3-matplotlib python3-distributed
  clang libclang-rt-14-dev  # libFuzzer + sanitizers for scripts/run-fuzz.sh (make fuzz)
)

missing=()
for p in "${PACKAGES[@]}"; do
  # dpkg-query prints "install ok installed" only for fully installed packages.
  if [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" != "install ok installed" ]; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
