#!/usr/bin/env bash
# Prints the path of a Python VERSION (e.g. 3.11) on this machine that can make venvs (venv and
# ensurepip), with its C headers too when --headers is given; exits 1, printing nothing, when
# there is none. pyenv's (first on PATH here) is preferred to Debian's /usr/bin/pythonX.Y, and
# that to the one scripts/build-python.sh built; with --build, one is built when none is found
# (Debian 12 has no 3.13, which Blender 5.1+ runs).
#   scripts/find-python.sh VERSION [--headers] [--build]
# Used by build-wheels.sh (the wheels' build) and bpy-venv.sh (PyPI's bpy).
set -uo pipefail
VERSION=$1
shift
HEADERS="" BUILD=""
for arg in "$@"; do
  case "$arg" in
    --headers) HEADERS=--headers ;;
    --build) BUILD=1 ;;
  esac
done
CHECK='
import os, sys, sysconfig, venv, ensurepip
assert "%d.%d" % sys.version_info[:2] == sys.argv[1]
assert sys.argv[2] != "--headers" or os.path.isfile(
    os.path.join(sysconfig.get_paths()["include"], "Python.h"))'
BUILT=${DCG_PYTHON_CACHE:-$HOME/.cache/dcg-rig}/python-$VERSION/bin/python$VERSION
found() {
  for cand in "python$VERSION" "/usr/bin/python$VERSION" "$BUILT"; do
    if command -v "$cand" >/dev/null 2>&1 &&
       "$cand" -c "$CHECK" "$VERSION" "$HEADERS" >/dev/null 2>&1; then
      command -v "$cand"
      return 0
    fi
  done
  return 1
}
found && exit 0
[ -n "$BUILD" ] || exit 1
bash "$(dirname "$0")/build-python.sh" "$VERSION" >&2 || exit 1
found
