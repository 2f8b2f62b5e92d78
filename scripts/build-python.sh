#!/usr/bin/env bash
# Builds (once) a CPython VERSION for a machine whose distribution has none, and prints its
# path: Blender 5.1+ runs Python 3.13, so its bpy and the extension's cp313 wheel need one, and
# Debian 12 has only 3.11.
#   scripts/build-python.sh VERSION       e.g. scripts/build-python.sh 3.13
# The source is the upstream tarball Debian builds its pythonVERSION from (13, trixie: 3.13;
# 12, bookworm: 3.11), found in that release's Sources index on deb.debian.org and checked
# against the SHA-256 listed there. It is built with its shared library, headers, venv and
# ensurepip into $DCG_PYTHON_CACHE/python-VERSION (default ~/.cache/dcg-rig), so a fresh clone
# on the same machine finds it and builds nothing (about 2 minutes on 2 cores the first time;
# the log beside it). Exit status 3, with the reason on stdout, when the source cannot be
# fetched or does not build (a source that failed to build is not tried again).
set -euo pipefail
VERSION=$1
PREFIX=${DCG_PYTHON_CACHE:-$HOME/.cache/dcg-rig}/python-$VERSION
PY=$PREFIX/bin/python$VERSION
if [ -f "$PREFIX/.complete" ]; then
  echo "$PY"
  exit 0
fi
MIRROR=${DCG_DEBIAN_MIRROR:-http://deb.debian.org/debian}
WORK=$PREFIX.build
LOG=$PREFIX.log
rm -rf "$WORK" "$PREFIX"
mkdir -p "$WORK"
: >"$LOG"
fail() { rm -rf "$WORK" "$PREFIX"; echo "build-python: $1 (log: $LOG)"; exit 3; }

# "DIRECTORY SHA256 FILE" of pythonVERSION's orig tarball in a Sources index on stdin.
orig_tarball() {
  awk -v pkg="python$VERSION" '
    $0 == "Package: " pkg { inside = 1; next }
    inside && /^Package: / { exit }
    inside && /^Directory: / { dir = $2 }
    inside && /^Checksums-Sha256:/ { sums = 1; next }
    inside && sums && /^ / { if ($3 ~ /\.orig\.tar\.(xz|gz)$/) { sha = $1; file = $3 }; next }
    inside && sums { sums = 0 }
    END { if (file) print dir, sha, file }'
}

FILE=""
for suite in trixie bookworm; do
  curl -fsS --max-time 120 -o "$WORK/Sources.xz" \
    "$MIRROR/dists/$suite/main/source/Sources.xz" 2>>"$LOG" || continue
  read -r DIRECTORY SHA FILE < <(xz -dc "$WORK/Sources.xz" | orig_tarball) || true
  [ -n "${FILE:-}" ] && break
done
[ -n "${FILE:-}" ] ||
  fail "no Python $VERSION here, and no source for one in Debian's indexes (or out of reach)"
curl -fsS --max-time 600 -o "$WORK/$FILE" "$MIRROR/$DIRECTORY/$FILE" 2>>"$LOG" ||
  fail "could not fetch $FILE"
echo "$SHA  $WORK/$FILE" | sha256sum -c --quiet - >>"$LOG" 2>&1 || fail "$FILE: SHA-256 mismatch"

# A source that did not build here once is not built again at every `make test`.
FAILED=$PREFIX.failed
if [ "$(cat "$FAILED" 2>/dev/null)" = "$FILE" ]; then
  fail "$FILE did not build here before (delete $FAILED to try again)"
fi
echo "build-python: building Python $VERSION from $FILE into $PREFIX (log: $LOG)" >&2
tar -xf "$WORK/$FILE" -C "$WORK"
SOURCE=$(find "$WORK" -mindepth 1 -maxdepth 1 -type d -name 'Python-*' | head -1)
[ -n "$SOURCE" ] || fail "$FILE holds no Python-* folder"
if ! (cd "$SOURCE" &&
      ./configure --prefix="$PREFIX" --enable-shared LDFLAGS="-Wl,-rpath,$PREFIX/lib" &&
      make -j"${JOBS:-2}" && make install) >>"$LOG" 2>&1; then
  echo "$FILE" >"$FAILED"
  fail "Python $VERSION did not build"
fi
if ! "$PY" -c 'import ssl, venv, ensurepip, zlib, ctypes' >>"$LOG" 2>&1; then
  echo "$FILE" >"$FAILED"
  fail "the built Python $VERSION lacks ssl, zlib or ctypes (their -dev packages)"
fi
rm -rf "$WORK"
touch "$PREFIX/.complete"
echo "$PY"
