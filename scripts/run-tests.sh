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

# Each suite's header says when it started (seconds since this script began), so that a slow
# CI run shows where its time went.
header() { echo "== $1 [at ${SECONDS} s]"; }

# The C++ sources as clang-format (the pinned version of scripts/clang-format.sh) writes them:
# suite `format`, one test per file.
header "Format (clang-format)"
bash scripts/clang-format.sh --check "$RESULTS/format.xml" 2>"$RESULTS/format.log" ||
  tail -3 "$RESULTS/format.log"

header "C++ tests (ctest)"
ctest --test-dir "$BUILD" --output-on-failure -j2 --output-junit "$RESULTS/cpp.xml"

# The C++ tests again under AddressSanitizer + UndefinedBehaviorSanitizer, in their own build
# folder (beside $BUILD). The tests on the public meshes and the two that rerun the pipeline
# under many random rotations, scales and noise draws are left out here: they run above, and
# under the sanitizers they added four minutes without new code paths. SANITIZE=0 skips this
# suite (for quick local runs; CI runs it).
SUMMARY_FILES=("$RESULTS/format.xml" "$RESULTS/cpp.xml")
if [ "${SANITIZE:-1}" != 0 ]; then
  header "C++ tests under ASan + UBSan (build, then run)"
  ASAN_BUILD="$BUILD-asan"
  if [ ! -f "$ASAN_BUILD/build.ninja" ]; then
    # -g1: line tables only, enough for the sanitizers' stack traces; full -g made compiling
    # the CGAL translation units much slower.
    cmake -S . -B "$ASAN_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDCG_SANITIZE=ON \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
      -DPython_EXECUTABLE=/usr/bin/python3 > /dev/null
  fi
  if cmake --build "$ASAN_BUILD" --target dcg_tests -j"${JOBS:-2}" > "$RESULTS/asan-build.log" 2>&1; then
    echo "built [at ${SECONDS} s]"
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
      "$ASAN_BUILD/dcg_tests" --gtest_filter='-*Public*:*RotationScaleAndNoise*' --gtest_brief=1 \
      --gtest_output="xml:$RESULTS/cpp-asan.xml" || true
  else
    tail -30 "$RESULTS/asan-build.log"
  fi
  SUMMARY_FILES+=("$RESULTS/cpp-asan.xml")
else
  echo "== C++ tests under ASan + UBSan: skipped (SANITIZE=0)"
fi

# libFuzzer on the mesh readers, stage 0 and the whole engine (clang, build-fuzz/ beside $BUILD)
# for FUZZ_SECONDS (90) in all, after replaying the regression inputs of tests/fuzz/corpus/; suite `fuzz` (pass =
# no crash). Reported as skipped when clang is missing; FUZZ=0 leaves it out.
if [ "${FUZZ:-1}" != 0 ]; then
  header "Fuzzing (libFuzzer, ${FUZZ_SECONDS:-90} s, after its build)"
  FUZZ_BUILD="$BUILD-fuzz" bash scripts/run-fuzz.sh "${FUZZ_SECONDS:-90}" "$RESULTS/fuzz.xml"
  SUMMARY_FILES+=("$RESULTS/fuzz.xml")
else
  echo "== Fuzzing: skipped (FUZZ=0)"
fi

header "Python tests (pytest, /usr/bin/python3)"
PYTHONPATH="$BUILD/python" /usr/bin/python3 -m pytest tests/python -q -p no:cacheprovider \
  --junitxml="$RESULTS/python.xml"

# The Blender suite on every Blender this machine can run. The distribution's `blender` (3.4 on
# Debian 12) gets the legacy add-on of the build output; PyPI's `bpy` of each series in
# BPY_SERIES (one venv each, .venv/bpy-<series>, made once) gets the extension zip
# ($EXTENSION, made by `make extension`), installed into a clean temporary user folder. A
# Blender that cannot run here is one skipped test in the count, with its reason.
BLENDER_FILES=()
skip_suite() {  # file suite reason
  /usr/bin/python3 scripts/test_summary.py --skip "$1" "$2" "$3"
  echo "skipped: $3"
}
# blender_suite RESULT EXTENSION COMMAND...: blender_tests/run.py under COMMAND (a Blender
# application's `blender -b ... --python`, or a bpy venv's python), with the extension zip
# EXTENSION installed into a clean temporary user folder, or with the build output's legacy
# add-on when EXTENSION is empty.
blender_suite() {
  local result=$1 extension=$2 user
  shift 2
  user=$(mktemp -d)
  if [ -n "$extension" ]; then
    BLENDER_USER_RESOURCES="$user" DCG_EXTENSION="$extension" "$@" blender_tests/run.py -- \
      --junitxml "$result"
  else
    BLENDER_USER_SCRIPTS="$BUILD/blender_scripts" DCG_PYTHONPATH="$BUILD/python" "$@" \
      blender_tests/run.py -- --junitxml "$result"
  fi 2>&1 | grep -v -e '^Read prefs' -e '^Blender quit' -e '^$' || true
  rm -rf "$user"
}
BLENDER_APP=(blender -b --factory-startup --python-exit-code 1 --python)

EXTENSION=${EXTENSION:-$(ls -t "$ROOT"/out/dcg_rig-*.zip 2>/dev/null | head -1)}
BLENDER_RESULT="$RESULTS/blender-debian.xml"
DEBIAN_BLENDER=$(blender -b --factory-startup --python-expr \
  'import bpy; print("DCG-VERSION %d.%d" % bpy.app.version[:2])' 2>/dev/null |
  sed -n 's/^DCG-VERSION //p' || true)
if [ -z "$DEBIAN_BLENDER" ]; then
  header "Blender tests: the distribution's blender"
  skip_suite "$BLENDER_RESULT" blender-debian "no working blender on PATH"
elif [ "$(printf '4.2\n%s\n' "$DEBIAN_BLENDER" | sort -V | head -1)" = 4.2 ] && [ -n "$EXTENSION" ]; then
  # 4.2 or later (Debian 13's 4.3): the extension, as its users install it.
  header "Blender tests: the distribution's blender $DEBIAN_BLENDER (the extension)"
  blender_suite "$BLENDER_RESULT" "$EXTENSION" "${BLENDER_APP[@]}"
else
  header "Blender tests: the distribution's blender $DEBIAN_BLENDER (legacy add-on)"
  blender_suite "$BLENDER_RESULT" "" "${BLENDER_APP[@]}"
fi
BLENDER_FILES+=("$BLENDER_RESULT")

for series in ${BPY_SERIES:-4.2 4.5 5.0 5.1 5.2 5.3}; do
  result="$RESULTS/blender-bpy-$series.xml"
  BLENDER_FILES+=("$result")
  header "Blender tests: bpy $series (the extension)"
  if [ -z "$EXTENSION" ]; then
    skip_suite "$result" "blender-bpy-$series" "no extension zip (make extension)"; continue
  fi
  if ! reason=$(bash scripts/bpy-venv.sh "$series" "$ROOT/.venv/bpy-$series" 2>"$RESULTS/bpy-$series-venv.log"); then
    skip_suite "$result" "blender-bpy-$series" "bpy $series: ${reason:-$(tail -1 "$RESULTS/bpy-$series-venv.log")}"
    continue
  fi
  blender_suite "$result" "$EXTENSION" "$ROOT/.venv/bpy-$series/bin/python"
done

header "Summary"
exec /usr/bin/python3 scripts/test_summary.py "${SUMMARY_FILES[@]}" "$RESULTS/python.xml" \
  "${BLENDER_FILES[@]}"
