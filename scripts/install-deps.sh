#!/usr/bin/env bash
# Installs the Debian packages dcg-rig needs, only those that are missing.
# Idempotent: when everything is present it prints nothing and returns at once.
# Run as root (or with sudo available). The Python packages of the development build come from
# apt; the wheel's build tools and PyPI's bpy go into the project's venvs (build-wheels.sh,
# bpy-venv.sh), for which python3-venv is here.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build ccache
  libcgal-dev libembree-dev libeigen3-dev libtbb-dev libgmp-dev libmpfr-dev libboost-dev
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
  libgtest-dev libbenchmark-dev
  blender python3-matplotlib python3-distributed python3-venv
  # What Blender needs to render headlessly (make rig's picture) and to load as PyPI's bpy;
  # a minimal Debian lacks them (Couldn't open libEGL.so.1).
  libegl1 libgl1 libx11-6 libxrender1 libxxf86vm1 libxfixes3 libxi6 libxkbcommon0 libsm6
  clang libclang-rt-dev  # libFuzzer + sanitizers for scripts/run-fuzz.sh (make fuzz)
  # What scripts/build-python.sh needs to fetch and build a Python the distribution lacks
  # (Debian 12: 3.13 for Blender 5.1+): pip's ssl, zlib, ctypes and the archive modules.
  curl xz-utils libssl-dev zlib1g-dev libffi-dev libbz2-dev liblzma-dev libsqlite3-dev
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
