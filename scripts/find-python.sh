#!/usr/bin/env bash
# Prints the path of a Python VERSION (e.g. 3.11) on this machine that can make venvs (venv and
# ensurepip), with its C headers too when --headers is given; exits 1, printing nothing, when
# there is none. pyenv's (first on PATH here) is preferred to Debian's /usr/bin/pythonX.Y.
#   scripts/find-python.sh VERSION [--headers]
# Used by build-wheels.sh (the wheels' build) and bpy-venv.sh (PyPI's bpy).
set -uo pipefail
VERSION=$1
CHECK='
import os, sys, sysconfig, venv, ensurepip
assert "%d.%d" % sys.version_info[:2] == sys.argv[1]
assert sys.argv[2] != "--headers" or os.path.isfile(
    os.path.join(sysconfig.get_paths()["include"], "Python.h"))'
for cand in "python$VERSION" "/usr/bin/python$VERSION"; do
  if command -v "$cand" >/dev/null 2>&1 &&
     "$cand" -c "$CHECK" "$VERSION" "${2:-}" >/dev/null 2>&1; then
    command -v "$cand"
    exit 0
  fi
done
exit 1
