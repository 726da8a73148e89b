#!/usr/bin/env bash
# Checks the README's commands on a new machine, played by a fresh debootstrap root:
#   test/install/fresh-root.sh bookworm   (Debian 12 with Debian's opam package installed
#                                          but never initialised: the toolchain root)
#   test/install/fresh-root.sh trixie     (Debian 13: the native path)
#   test/install/fresh-root.sh trixie-pending  (Debian 13 with trixie-security and
#                                          trixie-updates configured, updates pending)
#   test/install/fresh-root.sh bookworm-user   (Debian 12: make install, then the README's
#                                          and the golden-test guide's commands from a
#                                          project outside the tree)
#   test/install/fresh-root.sh trixie-cluster  (Debian 13 with MPICH standing for a
#                                          cluster's own MPI: the cluster guide's build of
#                                          lancer-mpi against it, with the OCaml of the
#                                          system; then the same as bookworm-user)
# It makes the root (with gcc and make, as a user's machine has) under $TMPDIR, copies
# the project's tracked files into it, records its packages and /etc/apt, runs
# `make test`, `make demo` and `make test` again (timed), then checks that no package of
# the root moved or went away, that nothing under /etc/apt changed, and that gcc still
# compiles a file with a 256-byte constant table. With trixie-pending, `make demo` and
# `make test` must instead stop at once, change nothing, and name the fix (apt-get
# upgrade). The -user and -cluster cases run, instead of the make targets, the blocks of
# the pages marked `route=NAME` word for word: the files they show are written into
# ~/my-scenes, outside the tree, and their commands run there, after `make install` in
# the tree for -user; then the renders over MPI ranks must be lancer's bytes and the
# golden test must fail once the scene changes. Needs root and debootstrap; takes about
# ten minutes and 3 GB, removed at the end (KEEP=1 keeps the root).
set -euo pipefail
case=${1:?usage: fresh-root.sh bookworm|trixie|trixie-pending|bookworm-user|trixie-cluster}
dist=${case%%-*}
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
# The blocks of a page marked route=NAME: route_files writes those with file=F into DIR,
# route_commands prints the lines of the sh ones.
route_files() {
  awk -v want="route=$2" -v dir="$3" '
    /^```/ && !inside { inside = 1; take = 0; file = ""
      for (i = 2; i <= split($0, w, " "); i++) { if (w[i] == want) take = 1; if (w[i] ~ /^file=/) file = substr(w[i], 6) }
      if (!take || file == "") take = 0; else out = dir "/" file
      next }
    /^```/ { inside = 0; if (take) close(out); next }
    inside && take { print > out }' "$top/$1"
}
route_commands() {
  awk -v want="route=$2" '
    /^```/ && !inside { inside = 1; take = 0
      for (i = 2; i <= split($0, w, " "); i++) if (w[i] == want) take = 1
      if ($0 !~ /^```(sh|bash) /) take = 0
      next }
    /^```/ { inside = 0; next }
    inside && take { print }' "$top/$1"
}
user="$r/root/my-scenes"
if [ "$case" = trixie-cluster ]; then
  # The cluster's MPI, installed by its administrators before anything of lancer's.
  inroot 'apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends mpich libmpich-dev' >"$logs/mpich.log" 2>&1 ||
    { tail "$logs/mpich.log"; exit 1; }
  inroot 'dpkg-query -W -f "\${Package} \${Version}\n" | sort' >"$work/dpkg-before"
fi
if [ "$case" = bookworm-user ] || [ "$case" = trixie-cluster ]; then
  mkdir -p "$user"
  route_files README.md user "$user"
  route_files doc/howto/golden-tests.md golden "$user"
  cp "$user/first.rts" "$user/scene.rts"
  { echo 'set -ex'; route_commands doc/howto/golden-tests.md golden; } >"$r/root/route-golden.sh"
  { echo 'set -ex'; route_commands README.md user; } >"$r/root/route-user.sh"
  { echo 'set -ex'; route_commands doc/howto/cluster.md cluster; } >"$r/root/route-cluster.sh"
  for f in route-golden route-user route-cluster; do
    [ "$(grep -vc '^set -ex$' "$r/root/$f.sh")" -gt 0 ] || { echo "fresh-root: no commands for $f in the pages"; exit 1; }
  done
  ls "$user"/{dune-project,dune,test_scenes.ml,ball.rts,first.rts} >/dev/null
fi
path='PATH=$HOME/.local/bin:$PATH'
if [ "$case" = bookworm-user ] || [ "$case" = trixie-cluster ]; then
  if [ "$case" = bookworm-user ]; then
    [ "$(inroot 'cd /home/user/lancer && bash .ci/toolchain mode')" = root ] ||
      { echo "fresh-root: with opam installed but not initialised, the mode is not root"; exit 1; }
    step make-install 'make install'
  else
    # make install there, then a render over two ranks of the cluster's MPI.
    step cluster-route "export $path; bash ~/route-cluster.sh"
    step cluster-mpi "export $path; cd ~/my-scenes && ldd \$(command -v lancer-mpi) | grep mpich &&
      lancer render scene.rts -o ref.png -q && cmp ref.png scene.png"
  fi
  step golden-route "export $path; cd ~/my-scenes && bash ~/route-golden.sh && test -s golden/ball.png"
  step readme-route "export $path; cd ~/my-scenes && bash ~/route-user.sh"
  step mpi-bytes "export $path; cd ~/my-scenes && lancer render first.rts -o first.png -q && cmp first.png first-mpi.png"
  # Ctrl-C, as a terminal sends it (to the whole process group), ends the job with 130
  # within 2 s through everything that runs it.
  step mpirun-interrupt "export $path; cd ~/my-scenes && rm -f status &&
    { setsid bash -c 'lancer-mpirun -n 2 lancer-mpi render first.rts -o big.png --width 8000 --height 6000 -q; echo \$? >status' & } &&
    sleep 2 && kill -INT -- -\$! && for i in \$(seq 20); do [ -s status ] && break; sleep 0.1; done &&
    cat status && [ \$(cat status) = 130 ] && [ ! -e big.png ]"
  step golden-catches-change "export $path; cd ~/my-scenes && sed -i 's/0.15, 0.35, 0.9/0.2, 0.8, 0.2/' ball.rts &&
    ! lancer-env dune test >changed.log 2>&1 && grep 'differs from its golden' changed.log"
elif [ "$case" = trixie-pending ]; then
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
