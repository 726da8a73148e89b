#!/usr/bin/env bash
# Checks the README's two commands on a new machine, played by a fresh debootstrap root:
#   test/install/fresh-root.sh bookworm   (Debian 12 with Debian's opam package installed
#                                          but never initialised: the toolchain root)
#   test/install/fresh-root.sh trixie     (Debian 13: the native path)
#   test/install/fresh-root.sh trixie-pending  (Debian 13 with trixie-security and
#                                          trixie-updates configured, updates pending)
# It makes the root (with gcc and make, as a user's machine has) under $TMPDIR, copies
# the project's tracked files into it, records its packages and /etc/apt, runs
# `make test`, `make demo` and `make test` again (timed), then checks that no package of
# the root moved or went away, that nothing under /etc/apt changed, and that gcc still
# compiles a file with a 256-byte constant table. With trixie-pending, `make demo` and
# `make test` must instead stop at once, change nothing, and name the fix (apt-get
# upgrade). Needs root and debootstrap; takes about ten minutes and 3 GB, removed at the
# end (KEEP=1 keeps the root).
set -euo pipefail
case=${1:?usage: fresh-root.sh bookworm|trixie|trixie-pending}
dist=${case%-pending}
extra=gcc,make,libc6-dev
[ "$dist" = bookworm ] && extra=$extra,opam
top=$(cd "$(dirname "$0")/../.." && pwd)
[ "$(id -u)" = 0 ] || { echo "fresh-root: needs root (debootstrap, chroot)" >&2; exit 1; }
uri=$(grep -h '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}' |
  grep -v -- -security | grep -i debian | head -n 1 || true)
[ -n "$uri" ] || uri=$(grep -E '^deb ' /etc/apt/sources.list | grep -v -- -security | awk '{print $2}' | head -n 1)
work=$(mktemp -d "${TMPDIR:-/tmp}/lancer-fresh-$dist.XXXXXX")
r="$work/root"
logs=${LOGS:-${TMPDIR:-/tmp}/lancer-fresh-$dist-logs}   # kept after the root is removed
rm -rf "$logs"; mkdir -p "$logs"
cleanup() { [ "${KEEP:-0}" = 1 ] && { echo "kept $r"; return; }; rm -rf --one-file-system "$work"; }
trap cleanup EXIT
t0=$(date +%s)
debootstrap --include="$extra" "$dist" "$r" "$uri" >"$work/debootstrap.log" 2>&1 ||
  { tail "$work/debootstrap.log"; exit 1; }
echo 'Acquire::Check-Valid-Until "false";' >"$r/etc/apt/apt.conf.d/90frozen-archive"
echo "fresh-root: $dist root made in $(( $(date +%s) - t0 )) s"
if [ "$case" = trixie-pending ]; then
  sec=$(grep -h '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}' |
    grep -- -security | head -n 1 || true)
  [ -n "$sec" ] || sec=${uri%/debian}/debian-security
  printf 'deb %s trixie main\ndeb %s trixie-updates main\ndeb %s trixie-security main\n' \
    "$uri" "$uri" "$sec" >"$r/etc/apt/sources.list"
fi
mkdir -p "$r/home/user/lancer"
(cd "$top" && git ls-files -z | xargs -0 cp -a --parents -t "$r/home/user/lancer")
cat >"$r/home/user/table.c" <<'C'
const unsigned char table[256] = {
#define R(i) i, i+1, i+2, i+3, i+4, i+5, i+6, i+7, i+8, i+9, i+10, i+11, i+12, i+13, i+14, i+15,
R(0) R(16) R(32) R(48) R(64) R(80) R(96) R(112) R(128) R(144) R(160) R(176) R(192) R(208) R(224) R(240)
};
C
inroot() {
  unshare --mount --propagation private --fork /bin/bash -c '
    r=$1; shift
    mount --bind "$r" "$r"   # as on a real machine, the root is a mount point
    mount -t proc proc "$r/proc"; mount --rbind /dev "$r/dev"; mount --rbind /sys "$r/sys"
    exec chroot "$r" /usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
      HOME=/root TERM=dumb LANG=C.UTF-8 /bin/bash -c "$*"' bash "$r" "$@"
}
inroot 'dpkg-query -W -f "\${Package} \${Version}\n" | sort' >"$work/dpkg-before"
inroot 'find /etc/apt -type f -print0 | sort -z | xargs -0 md5sum' >"$work/apt-before"
step() {
  local name=$1; shift
  local s; s=$(date +%s)
  if inroot "cd /home/user/lancer && $*" >"$logs/$name.log" 2>&1; then
    echo "fresh-root: $name passed in $(( $(date +%s) - s )) s"
  else
    echo "fresh-root: $name FAILED after $(( $(date +%s) - s )) s; its log ends:"; grep -B2 -A12 -E 'FAIL|Error' "$logs/$name.log" | head -n 60; echo "(whole log: $logs/$name.log)"; exit 1
  fi
}
if [ "$case" = trixie-pending ]; then
  inroot 'apt-get update -q' >/dev/null
  pending=$(inroot 'apt-get -s upgrade' | grep -c '^Inst ' || true)
  echo "fresh-root: $pending updates pending"
  [ "$pending" -gt 0 ] || { echo "fresh-root: no update pending in these suites today: nothing to check"; exit 0; }
  for t in demo test; do
    s=$(date +%s)
    if inroot "cd /home/user/lancer && make $t" >"$logs/make-$t.log" 2>&1; then
      echo "fresh-root: make $t went on with updates pending"; cat "$logs/make-$t.log"; exit 1
    fi
    grep -q 'apt-get update && apt-get upgrade' "$logs/make-$t.log" ||
      { echo "fresh-root: make $t failed without naming the fix:"; cat "$logs/make-$t.log"; exit 1; }
    echo "fresh-root: make $t stopped after $(( $(date +%s) - s )) s, naming the fix"
  done
else
  [ "$dist" != bookworm ] || [ "$(inroot 'cd /home/user/lancer && bash .ci/toolchain mode')" = root ] ||
    { echo "fresh-root: with opam installed but not initialised, the mode is not root"; exit 1; }
  step make-test 'make test'
  step make-demo 'make demo && test -s out/showcase.png && out/bin/lancer --version'
  step make-test-again 'make test'
fi
inroot 'dpkg-query -W -f "\${Package} \${Version}\n" | sort' >"$work/dpkg-after"
inroot 'find /etc/apt -type f -print0 | sort -z | xargs -0 md5sum' >"$work/apt-after"
fail=0
moved=$(join -j1 <(sort "$work/dpkg-before") <(sort "$work/dpkg-after") | awk '$2 != $3' || true)
gone=$(comm -23 <(cut -d' ' -f1 "$work/dpkg-before" | sort) <(cut -d' ' -f1 "$work/dpkg-after" | sort))
added=$(comm -13 <(cut -d' ' -f1 "$work/dpkg-before" | sort) <(cut -d' ' -f1 "$work/dpkg-after" | sort) | tr '\n' ' ')
[ -z "$moved" ] || { echo "fresh-root: packages changed version:"; echo "$moved"; fail=1; }
[ -z "$gone" ] || { echo "fresh-root: packages removed:"; echo "$gone"; fail=1; }
echo "fresh-root: packages added: ${added:-none}"
if ! diff "$work/apt-before" "$work/apt-after"; then echo "fresh-root: /etc/apt changed"; fail=1; fi
if inroot 'cd /home/user && gcc -O2 -c table.c -o table.o'; then echo "fresh-root: gcc still compiles table.c"
else echo "fresh-root: gcc no longer compiles table.c"; fail=1; fi
echo "fresh-root: disk: project $(du -sh "$r/home/user/lancer" | cut -f1), of which toolchain $(du -sh "$r/home/user/lancer/_toolchain" 2>/dev/null | cut -f1 || echo none), _build $(du -sh "$r/home/user/lancer/_build" 2>/dev/null | cut -f1 || echo none)"
[ $fail = 0 ] && echo "fresh-root: $dist: all checks passed" || { echo "fresh-root: $dist: FAILED"; exit 1; }
