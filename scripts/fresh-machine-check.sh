#!/usr/bin/env bash
# The README's two commands on a truly fresh machine: a minimal Debian root (debootstrap
# --variant=minbase, plus git, make and CA certificates, nothing else), this repository cloned
# into it beside a copy of ../shared, then `make rig` and `make test` inside it (chroot, as
# root). Run by hand, it takes an hour or more and about 8 GB:
#
#   scripts/fresh-machine-check.sh [SUITE] [FOLDER]      SUITE: bookworm (Debian 12, default
#                                                        here) or trixie (Debian 13)
#
# It ends with the two commands' closing lines; the whole log is FOLDER.log. The root stays in
# FOLDER (default /var/tmp/dcg-fresh-SUITE) for a look inside; run again to start afresh, or
# with REUSE=1 to keep the root (and what it installed and built) and only bring the clone up
# to this repository's HEAD. The machine's CA certificates and pip's settings for them
# (PIP_CERT) are carried in, as a new machine of this workplace has them.
set -euo pipefail
SUITE=${1:-$(. /etc/os-release && echo "$VERSION_CODENAME")}
ROOT=${2:-/var/tmp/dcg-fresh-$SUITE}
REPO=$(cd "$(dirname "$0")/.." && pwd)
SHARED=$(realpath -m "$REPO/../shared")
LOG=$ROOT.log

[ "$(id -u)" -eq 0 ] || { echo "fresh-machine-check: run as root (debootstrap, chroot)" >&2; exit 1; }
command -v debootstrap >/dev/null || apt-get install -y -qq debootstrap >/dev/null

cleanup() {
  for m in proc sys dev/pts dev work/shared; do umount -l "$ROOT/$m" 2>/dev/null || true; done
}
trap cleanup EXIT
cleanup
if [ "${REUSE:-0}" = 1 ] && [ -d "$ROOT/work/dcg-rig/.git" ]; then
  echo "fresh-machine-check: reusing $ROOT (log: $LOG)"
  : > "$LOG"
  git -C "$ROOT/work/dcg-rig" fetch -q "$REPO" HEAD
  git -C "$ROOT/work/dcg-rig" reset -q --hard FETCH_HEAD
else
  rm -rf "$ROOT"
  echo "fresh-machine-check: debootstrap $SUITE into $ROOT (log: $LOG)"
  debootstrap --variant=minbase --include=git,make,ca-certificates "$SUITE" "$ROOT" \
    http://deb.debian.org/debian > "$LOG" 2>&1
  git clone -q "$REPO" "$ROOT/work/dcg-rig"
fi
cp /etc/ssl/certs/ca-certificates.crt "$ROOT/etc/ssl/certs/dcg-host-ca.crt"
mount -t proc proc "$ROOT/proc"
mount --rbind /sys "$ROOT/sys"
mount --rbind /dev "$ROOT/dev"
cp /etc/resolv.conf "$ROOT/etc/resolv.conf"
mkdir -p "$ROOT/work/shared"
[ -d "$SHARED" ] && mount --bind -o ro "$SHARED" "$ROOT/work/shared"

run() {  # a command in the root, as a fresh login would (no pyenv, Debian's python3 first)
  chroot "$ROOT" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
    PIP_CERT=/etc/ssl/certs/dcg-host-ca.crt bash -c "cd /work/dcg-rig && $1" >> "$LOG" 2>&1
}
status=0
echo "fresh-machine-check: make rig"
if run "make rig"; then
  echo "make rig: ok: $(cd "$ROOT/work/dcg-rig/out" && echo spot.*)"
else
  echo "make rig: FAILED (see $LOG)"; status=1
fi
echo "fresh-machine-check: make test"
run "make test" || status=1
grep -E "^ *[a-z0-9.-]+: [0-9]+ passed|^total:" "$LOG" | tail -20
exit $status
