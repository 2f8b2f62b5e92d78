#!/usr/bin/env bash
# clang-format over the project's C++ (cpp/, bindings/, tests/cpp/, tests/fuzz/), one pinned
# version everywhere (PyPI's clang-format wheel in .venv/tools, made once; the wheel stays in
# $DCG_WHEEL_CACHE/tools so a fresh clone fetches nothing): Debian 12's clang-format 14 and
# Debian 13's 19 format differently, and a check must mean the same on both.
#   scripts/clang-format.sh              rewrite the files in place (make format)
#   scripts/clang-format.sh --check XML  write a JUnit suite `format`: one test per file, failing
#                                        when clang-format would change it (make test)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
VERSION=19.1.7
VENV=$ROOT/.venv/tools
CACHE=${DCG_WHEEL_CACHE:-$HOME/.cache/dcg-rig/wheels}/tools
if [ ! -f "$VENV/.complete-clang-format-$VERSION" ]; then
  rm -rf "$VENV"
  /usr/bin/python3 -m venv "$VENV"
  pip=("$VENV/bin/python" -m pip -q --disable-pip-version-check)
  if ! ls "$CACHE"/clang_format-"$VERSION"-*.whl >/dev/null 2>&1; then
    mkdir -p "$CACHE"
    "${pip[@]}" download --no-deps -d "$CACHE" "clang-format==$VERSION"
  fi
  "${pip[@]}" install --no-index --find-links "$CACHE" "clang-format==$VERSION"
  touch "$VENV/.complete-clang-format-$VERSION"
fi
cd "$ROOT"
mapfile -t FILES < <(git ls-files -- 'cpp/*.h' 'cpp/*.cpp' 'bindings/*.h' 'bindings/*.cpp' \
  'tests/cpp/*.h' 'tests/cpp/*.cpp' 'tests/fuzz/*.cpp')
if [ "${1:-}" != --check ]; then
  "$VENV/bin/clang-format" -i "${FILES[@]}"
  exit 0
fi
exec /usr/bin/python3 - "$VENV/bin/clang-format" "$2" "${FILES[@]}" <<'PY'
import subprocess, sys
import xml.etree.ElementTree as ET
tool, out, files = sys.argv[1], sys.argv[2], sys.argv[3:]
suite = ET.Element("testsuite", name="format", tests=str(len(files)))
bad = 0
for path in files:
    case = ET.SubElement(suite, "testcase", classname="format", name=path)
    run = subprocess.run([tool, "--dry-run", path], capture_output=True, text=True)
    # Any note on stderr is a change clang-format would make.
    if run.returncode or run.stderr.strip():
        bad += 1
        lines = run.stderr.strip().splitlines()
        ET.SubElement(case, "failure", message=f"clang-format would change {path} "
                      f"({len(lines)} lines of notes); run `make format`").text = "\n".join(lines[:20])
root = ET.Element("testsuites")
root.append(suite)
ET.ElementTree(root).write(out, encoding="unicode")
print(f"format: {len(files) - bad} of {len(files)} C++ files as clang-format writes them")
PY
