#!/usr/bin/env bash
# Runs every test suite against the build folder $1 (default build): ctest (C++), pytest on the
# bindings, and the Blender tests inside `blender -b`. Each suite writes JUnit XML into
# $BUILD/test-results/; the last line printed is the total over all suites:
#   total: N passed, N failed, N skipped
# and the exit code is non-zero when anything failed or a suite produced no results.
set -uo pipefail
BUILD=$(realpath "${1:-build}")
ROOT=$(cd "$(dirname "$0")/.." && pwd)
RESULTS=$BUILD/test-results
rm -rf "$RESULTS"
mkdir -p "$RESULTS"
cd "$ROOT"
export DCG_MESHES=${DCG_MESHES:-$(realpath -m "$ROOT/../shared/meshes")}
[ -d "$DCG_MESHES" ] || echo "note: $DCG_MESHES is absent: tests on the public meshes are skipped"

echo "== C++ tests (ctest)"
ctest --test-dir "$BUILD" --output-on-failure -j2 --output-junit "$RESULTS/cpp.xml"

echo "== Python tests (pytest, /usr/bin/python3)"
PYTHONPATH="$BUILD/python" /usr/bin/python3 -m pytest tests/python -q -p no:cacheprovider \
  --junitxml="$RESULTS/python.xml"

echo "== Blender tests (blender -b)"
BLENDER_USER_SCRIPTS="$BUILD/blender_scripts" DCG_PYTHONPATH="$BUILD/python" \
  blender -b --factory-startup --python-exit-code 1 --python blender_tests/run.py -- \
  --junitxml "$RESULTS/blender.xml" 2>&1 | grep -v -e '^Read prefs' -e '^Blender quit' \
  -e '^$' || true

echo "== Summary"
exec /usr/bin/python3 scripts/test_summary.py "$RESULTS/cpp.xml" "$RESULTS/python.xml" \
  "$RESULTS/blender.xml"
