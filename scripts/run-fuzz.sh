#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/: read_mesh, prepare, pipeline) in build-fuzz/ with
# clang and runs each for a share of SECONDS (default 90 in all), after replaying the regression
# inputs of tests/fuzz/corpus/.
# Writes JUnit XML (suite "fuzz", one test per target; pass = no crash, no sanitizer report,
# no timeout) to $2 when given. Without clang the suite is reported as skipped, with a note.
#   scripts/run-fuzz.sh [SECONDS] [RESULTS_XML]
# New inputs the fuzzer finds interesting go to build-fuzz/corpus/<target>/ (reused next time
# only with FUZZ_KEEP_CORPUS=1, as `make fuzz` does); a crashing input is saved as build-fuzz/artifacts/<target>/crash-*: once fixed, copy it
# into tests/fuzz/corpus/<target>/ so that every later run replays it.
set -uo pipefail
SECONDS_TOTAL=${1:-90}
XML=${2:-}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${FUZZ_BUILD:-$ROOT/build-fuzz}
TARGETS=(read_mesh prepare pipeline)
cd "$ROOT"

xml_escape() { sed -e 's/&/\&amp;/g' -e 's/</\&lt;/g' -e 's/>/\&gt;/g' -e 's/"/\&quot;/g' \
  | tr -cd '\11\12\15\40-\176'; }

# write_xml NAME STATUS SECONDS MESSAGE_FILE: one <testcase> (STATUS pass / fail / skip).
CASES=""
add_case() {
  local name=$1 status=$2 seconds=$3 detail=${4:-}
  local body=""
  if [ "$status" = fail ]; then
    body="<failure message=\"fuzz_$name found a crash\">$( [ -n "$detail" ] && tail -40 "$detail" | xml_escape)</failure>"
  elif [ "$status" = skip ]; then
    body="<skipped message=\"$(printf '%s' "$detail" | xml_escape)\"/>"
  fi
  CASES+="  <testcase classname=\"fuzz\" name=\"fuzz_$name\" time=\"$seconds\">$body</testcase>"$'\n'
}
finish() {
  [ -n "$XML" ] || return 0
  mkdir -p "$(dirname "$XML")"
  local tests failures skipped
  tests=$(grep -c '<testcase' <<< "$CASES")
  failures=$(grep -c '<failure' <<< "$CASES")
  skipped=$(grep -c '<skipped' <<< "$CASES")
  { echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo "<testsuite name=\"fuzz\" tests=\"$tests\" failures=\"$failures\" skipped=\"$skipped\">"
    printf '%s' "$CASES"
    echo '</testsuite>'; } > "$XML"
}

CXX_CLANG=$(command -v clang++ || true)
if [ -z "$CXX_CLANG" ]; then
  echo "note: clang++ not found (scripts/install-deps.sh installs it): the fuzz suite is skipped"
  for t in "${TARGETS[@]}"; do add_case "$t" skip 0 "clang++ not available"; done
  finish; exit 0
fi

mkdir -p "$BUILD"
if [ ! -f "$BUILD/build.ninja" ]; then
  cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$CXX_CLANG" \
    -DDCG_FUZZ=ON -DDCG_BUILD_TESTS=OFF -DDCG_BUILD_PYTHON=OFF \
    -DPython_EXECUTABLE=/usr/bin/python3 > "$BUILD/configure.log" 2>&1 \
    || { tail -20 "$BUILD/configure.log"; }
fi
if ! cmake --build "$BUILD" --target fuzz_targets -j"${JOBS:-2}" > "$BUILD/fuzz-build.log" 2>&1; then
  tail -30 "$BUILD/fuzz-build.log"
  for t in "${TARGETS[@]}"; do add_case "$t" fail 0 "$BUILD/fuzz-build.log"; done
  finish; exit 1
fi

status=0
per_target=$(( SECONDS_TOTAL / ${#TARGETS[@]} ))
[ "$per_target" -ge 1 ] || per_target=1
for t in "${TARGETS[@]}"; do
  corpus=$BUILD/corpus/$t
  artifacts=$BUILD/artifacts/$t
  # The inputs found by earlier runs are replayed before any new fuzzing, and libFuzzer cannot
  # stop during that replay: stage 0 runs a few inputs a second under the sanitizers, so a
  # corpus grown over long runs would eat a short budget. Short runs (make test) start again
  # from the repository's inputs; FUZZ_KEEP_CORPUS=1 (make fuzz) keeps growing it.
  [ "${FUZZ_KEEP_CORPUS:-0}" = 1 ] || rm -rf "$corpus"
  mkdir -p "$corpus" "$artifacts" "tests/fuzz/corpus/$t"
  log=$BUILD/fuzz_$t.log
  start=$(date +%s)
  # The first folder receives new inputs; the second (the repository's regression and seed
  # inputs) is read and replayed first.
  # Short runs (make test, CI) are reproducible: a fixed seed and a fixed number of inputs per
  # target (about half the time budget on a quiet 2-core machine), so that every machine tries
  # the same inputs in the same order and a CI failure replays locally; the time limit is only
  # a cap. Long runs (make fuzz) take a fresh seed each time and run for their time to explore.
  # FUZZ_SEED overrides the seed.
  seed_flag=()
  if [ -n "${FUZZ_SEED:-}" ]; then
    seed_flag=(-seed="$FUZZ_SEED")
  elif [ "${FUZZ_KEEP_CORPUS:-0}" != 1 ]; then
    seed_flag=(-seed=1)
  fi
  if [ "${FUZZ_KEEP_CORPUS:-0}" != 1 ]; then
    case $t in
      read_mesh) seed_flag+=(-runs=$(( per_target * 4000 ))) ;;
      prepare) seed_flag+=(-runs=$(( per_target * 100 ))) ;;
      pipeline) seed_flag+=(-runs=$(( per_target * 8 ))) ;;
    esac
  fi
  # -timeout: one input may take at most 20 s, 60 s for the whole engine (a 4-face sliver takes
  # 1 s in stage 0's wrap in a release build, 10-20 s under the sanitizers; a hang takes forever).
  timeout=20
  [ "$t" = pipeline ] && timeout=60
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
    "$BUILD/fuzz_$t" "${seed_flag[@]}" -max_total_time="$per_target" -timeout="$timeout" -rss_limit_mb=3072 \
    -max_len=4096 -print_final_stats=1 -artifact_prefix="$artifacts/" \
    "$corpus" "tests/fuzz/corpus/$t" > "$log" 2>&1
  rc=$?
  elapsed=$(( $(date +%s) - start ))
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
  if [ $rc -eq 0 ]; then
    echo "fuzz_$t: ${elapsed} s, ${runs} inputs, no crash"
    add_case "$t" pass "$elapsed"
  else
    echo "fuzz_$t: FAILED (exit $rc) after ${elapsed} s; input in $artifacts/; log $log"
    grep -E 'ERROR|SUMMARY|runtime error|deadly signal|Test unit written' "$log" | head -10
    add_case "$t" fail "$elapsed" "$log"
    status=1
  fi
done
finish
exit $status
