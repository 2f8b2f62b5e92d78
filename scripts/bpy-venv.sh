#!/usr/bin/env bash
# Makes (once) a virtual environment with PyPI's `bpy` (Blender as a Python module) of one
# Blender series, plus pytest, for the Blender suite:
#   scripts/bpy-venv.sh SERIES VENV      e.g. scripts/bpy-venv.sh 4.2 .venv/bpy-4.2
# SERIES is 4.2, 4.5, 5.0 (Python 3.11 wheels) or 5.1+ (Python 3.13). The newest patch release
# of the series is installed. An existing, complete venv is kept as it is (nothing is fetched);
# the downloaded wheels stay in $DCG_WHEEL_CACHE (default ~/.cache/dcg-rig/wheels/bpy-SERIES),
# so a venv made again (a fresh clone) installs from there and fetches nothing.
# Exit status 3, with the reason on stdout, when no matching Python is on this machine.
set -euo pipefail
SERIES=$1
VENV=$2
[ -f "$VENV/.complete" ] && exit 0

case "$SERIES" in
  4.*|5.0) PYVER=3.11 ;;
  *) PYVER=3.13 ;;
esac
if ! PY=$(bash "$(dirname "$0")/find-python.sh" "$PYVER" --build); then
  echo "no Python $PYVER with venv and ensurepip on this machine, nor one built by" \
    "scripts/build-python.sh (bpy $SERIES needs it)"
  exit 3
fi

CACHE=${DCG_WHEEL_CACHE:-$HOME/.cache/dcg-rig/wheels}/bpy-$SERIES
rm -rf "$VENV"
"$PY" -m venv "$VENV"
pip=("$VENV/bin/python" -m pip -q --disable-pip-version-check)
if ! ls "$CACHE"/bpy-*.whl >/dev/null 2>&1; then
  mkdir -p "$CACHE.part"
  "${pip[@]}" download -d "$CACHE.part" "bpy==$SERIES.*" pytest
  rm -rf "$CACHE" && mv "$CACHE.part" "$CACHE"
fi
"${pip[@]}" install --no-index --find-links "$CACHE" bpy pytest
touch "$VENV/.complete"
