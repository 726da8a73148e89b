#!/usr/bin/env bash
# lancer-mpirun: what it does with mpirun's arguments, status and signals, first with a
# stand-in mpirun (a script that records what it gets), then with Open MPI's own around
# lancer-mpi: a normal run, a failing one, and Ctrl-C, which plain mpirun reports as
# status 1 with no lancer message, and lancer-mpirun as 130 with one. Skipped, with the
# reason, where mpirun is missing (the stand-in part still runs).
#
# usage: launcher.sh SHOWCASE.rts   (lancer, lancer-mpi and lancer-mpirun on PATH)
set -u
showcase=$(realpath "$1")

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
here=$(pwd -P)
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }

command -v lancer-mpirun >/dev/null 2>&1 || { echo "FAIL: lancer-mpirun is not on PATH"; exit 1; }
launcher=$(command -v lancer-mpirun)

now_ms() { echo $(($(date +%s%N) / 1000000)); }
# the processes whose command line matches $1 and that run in this test's directory (the
# same test run elsewhere at once has processes of the same command line)
ours() {
  local p
  for p in $(pgrep -f -- "$1"); do
    [ "$(readlink "/proc/$p/cwd" 2>/dev/null)" = "$here" ] && echo "$p"
  done
  return 0
}
# waits up to 30 s until two ranks rendering into directory $1 run, then half a second
# more (a loaded machine may take seconds to start a job: the interrupt must find it running)
ranks_running() {
  local i
  for i in $(seq 1 300); do
    [ "$(ours "^[^ ]*lancer-mpi render branching.rts -o $1/" | wc -l)" -ge 2 ] && break
    sleep 0.1
  done
  sleep 0.5
}
# waits up to 10 s for pid $1 to end, then kills what is left; its status is in $status
wait_for() {
  local i
  for i in $(seq 1 200); do kill -0 "$1" 2>/dev/null || break; sleep 0.05; done
  if kill -0 "$1" 2>/dev/null; then kill -9 -- "-$1" 2>/dev/null; fi
  wait "$1"; status=$?
}

# ---- The launcher's own options.

if [ "$(lancer-mpirun --version)" = "$(lancer --version)" ] && lancer-mpirun --help=plain | grep -q '^NAME' \
   && lancer-mpirun --help=groff | grep -q '^\.TH "LANCER-MPIRUN" 1'; then
  ok "lancer-mpirun --version is lancer's, --help has a man page"
else fail "lancer-mpirun --version / --help"; fi

# ---- A stand-in mpirun: records its arguments and the signals it gets, then does what
# FAKE_DO says.
mkdir -p fakebin empty
cat >fakebin/mpirun <<'EOS'
#!/bin/bash
printf '%s\n' "$@" >args.txt
echo "$FAKE_NAME" >name.txt
trap 'echo INT >>signals.txt; exit "${FAKE_ON_SIGNAL:-1}"' INT
trap 'echo TERM >>signals.txt; exit "${FAKE_ON_SIGNAL:-1}"' TERM
trap 'echo HUP >>signals.txt; exit "${FAKE_ON_SIGNAL:-1}"' HUP
echo started >started.txt
case ${FAKE_DO:-exit0} in
  exit*) exit "${FAKE_DO#exit}" ;;
  kill9) kill -9 $$ ;;
  wait) for _ in $(seq 1 200); do sleep 0.05; done; exit 0 ;;
esac
EOS
chmod +x fakebin/mpirun
export FAKE_NAME=fakebin
fakepath="$work/fakebin:$PATH"
started() { for _ in $(seq 1 100); do [ -e started.txt ] && return; sleep 0.05; done; }

rm -f args.txt
FAKE_DO=exit0 PATH=$fakepath lancer-mpirun -np 2 --oversubscribe "a b" --help '' >/dev/null 2>&1; status=$?
if [ "$status" = 0 ] && [ "$(cat args.txt)" = "$(printf '%s\n' -np 2 --oversubscribe "a b" --help '')" ]; then
  ok "the arguments reach mpirun unchanged"
else fail "arguments: status $status, got: $(cat args.txt 2>/dev/null)"; fi

FAKE_DO=exit7 PATH=$fakepath lancer-mpirun -np 2 x >/dev/null 2>err.txt; status=$?
if [ "$status" = 7 ] && [ ! -s err.txt ]; then ok "mpirun's status is lancer-mpirun's (7), with nothing added"
else fail "status: $status"; cat err.txt; fi

FAKE_DO=kill9 PATH=$fakepath lancer-mpirun -np 2 x >/dev/null 2>err.txt; status=$?
if [ "$status" = 137 ] && grep -q 'killed by signal 9' err.txt; then ok "an mpirun killed by SIGKILL gives 128 + 9, said so"
else fail "mpirun killed: status $status"; cat err.txt; fi

mkdir -p other && cp fakebin/mpirun other/my-mpirun
FAKE_DO=exit3 FAKE_NAME=other LANCER_MPIRUN="$work/other/my-mpirun" PATH="$work/empty:/usr/bin:/bin" "$launcher" x \
  >/dev/null 2>&1; status=$?
if [ "$status" = 3 ] && [ "$(cat name.txt)" = other ]; then ok "LANCER_MPIRUN names the mpirun to run"
else fail "LANCER_MPIRUN: status $status"; fi

PATH="$work/empty" "$launcher" -np 2 x >/dev/null 2>err.txt; status=$?
if [ "$status" = 127 ] && grep -q '^lancer-mpirun: mpirun was not found on PATH' err.txt; then
  ok "no mpirun on PATH: status 127 and a message"
else fail "no mpirun: status $status"; cat err.txt; fi
LANCER_MPIRUN=/nonexistent/mpirun "$launcher" -np 2 x >/dev/null 2>err.txt; status=$?
if [ "$status" = 127 ] && grep -q '^lancer-mpirun: LANCER_MPIRUN=/nonexistent/mpirun: no such executable' err.txt; then
  ok "a missing LANCER_MPIRUN: status 127 and a message"
else fail "missing LANCER_MPIRUN: status $status"; cat err.txt; fi

# Signals sent to the launcher alone reach mpirun, and the launcher says it was
# interrupted; a job that finishes regardless keeps its status 0.
for sig in TERM HUP INT; do
  rm -f signals.txt started.txt
  FAKE_DO=wait PATH=$fakepath lancer-mpirun x >/dev/null 2>err.txt &
  pid=$!
  started
  kill -"$sig" "$pid"
  wait_for "$pid"
  if [ "$status" = 130 ] && [ "$(cat signals.txt 2>/dev/null)" = "$sig" ] && [ "$(tr -d '\0' <err.txt)" = "lancer-mpirun: interrupted" ]; then
    ok "SIG$sig to lancer-mpirun alone reaches mpirun once; status 130, one line"
  else fail "SIG$sig to the launcher: status $status, mpirun got: $(cat signals.txt 2>/dev/null)"; cat err.txt; fi
done
rm -f signals.txt started.txt
FAKE_DO=wait FAKE_ON_SIGNAL=0 PATH=$fakepath lancer-mpirun x >/dev/null 2>err.txt &
pid=$!
started
kill -TERM "$pid"
wait_for "$pid"
if [ "$status" = 0 ] && [ ! -s err.txt ]; then ok "an interrupted mpirun that still succeeds: status 0"
else fail "an mpirun succeeding after a signal: status $status"; cat err.txt; fi

# ---- Open MPI's mpirun around lancer-mpi.

if ! command -v mpirun >/dev/null 2>&1; then
  echo "FAIL: mpirun is not installed beside the MPI library lancer-mpi was built with (make deps installs openmpi-bin)"
  exit 1
fi
if ! lancer-mpi --help=plain >/dev/null 2>&1; then echo "FAIL: lancer-mpi is not on PATH"; exit 1; fi
export OMPI_MCA_pml=${OMPI_MCA_pml:-ob1}
export OMPI_MCA_btl=${OMPI_MCA_btl:-self,sm}
export OMPI_MCA_btl_base_warn_component_unused=${OMPI_MCA_btl_base_warn_component_unused:-0}
opts=(--oversubscribe)
[ "$(id -u)" = 0 ] && opts+=(--allow-run-as-root)

# The reference at the same depth: an image's record names its scene from its directory.
mkdir -p ref
lancer render "$showcase" --width 64 --height 48 -q -o ref/s.png >/dev/null || fail "lancer render"
mkdir -p good
timeout 60 lancer-mpirun "${opts[@]}" -np 2 lancer-mpi render "$showcase" --width 64 --height 48 -q -o good/s.png \
  >/dev/null 2>good.err
status=$?
if [ "$status" = 0 ] && cmp -s ref/s.png good/s.png && [ "$(ls -A good)" = s.png ]; then
  ok "a run through lancer-mpirun: status 0 and lancer render's image"
else fail "a normal run: status $status"; cat good.err; fi

printf 'sphere { center: (0, 1, 0) }\n' >bad.rts
timeout 60 lancer-mpirun "${opts[@]}" -np 2 lancer-mpi render bad.rts -o bad.png >/dev/null 2>bad.err
status=$?
if [ "$status" = 1 ] && [ "$(grep -c 'needs a `radius` field' bad.err)" = 1 ] && ! grep -q interrupted bad.err && [ ! -e bad.png ]; then
  ok "a scene error: mpirun's status 1, the error once, no image"
else fail "a scene error: status $status"; cat bad.err; fi

# A render that would take far longer than the test: three half-mirror, half-glass planes
# double a sample's rays at every bounce.
cat >branching.rts <<'EOS'
settings { width: 320, height: 240, depth: 1000 }
camera { position: (0, 0, -0.5), look_at: (1, 0.3, 0) }
light { position: (0, 5, -0.5) }
let m = material { reflection: 0.5, transparency: 0.5, ior: 1 }
plane { normal: (0, 0, 1), offset: -1, material: m }
plane { normal: (0, 0, 1), offset: 0, material: m }
plane { normal: (0, 0, 1), offset: 1, material: m }
EOS

# stop NAME HOW…: starts the long render through lancer-mpirun in a session (and so a
# process group) of its own, waits until its ranks run, sends the signals HOW says (group: SIGINT
# to the whole group, as a terminal's Ctrl-C; alone: SIGINT to lancer-mpirun's pid only),
# 0.1 s apart, then checks status 130 within 5 s, the message, and an empty directory.
stop() {
  local name=$1 t0 t1 how
  shift
  mkdir -p "$name"
  setsid lancer-mpirun "${opts[@]}" -np 2 lancer-mpi render branching.rts -o "$name/b.png" --domains 1 \
    >"$name.out" 2>"$name.err" &
  local pid=$!
  ranks_running "$name"
  t0=$(now_ms)
  for how in "$@"; do
    case $how in
      group) kill -INT -- "-$pid" 2>/dev/null ;;
      alone) kill -INT "$pid" 2>/dev/null ;;
    esac
    sleep 0.1
  done
  wait_for "$pid"
  t1=$(now_ms)
  if [ "$status" = 130 ] && [ $((t1 - t0)) -le 5000 ] && [ "$(tr -d '\0' <"$name.err" | tail -1)" = "lancer-mpirun: interrupted" ] \
     && [ -z "$(ls -A "$name")" ]; then
    ok "$name: status 130 after $((t1 - t0)) ms, the message, no image and no temporary file"
  else fail "$name: status $status after $((t1 - t0)) ms, files: $(ls -A "$name")"; cat "$name.err"; fi
}
stop "Ctrl-C on 2 ranks" group
stop "SIGINT to lancer-mpirun alone" alone
stop "Ctrl-C three times (mpirun's forcible termination)" group group group

# A real terminal, where util-linux's script(1) is there to give one: ^C typed into it
# reaches the terminal's foreground process group, lancer-mpirun and mpirun. script(1)
# runs the command with $SHELL: bash, which goes on after a child that handled the ^C
# (dash, /bin/sh, dies of it before printing the status). The terminal echoes the ^C as
# the two characters "^C", which may come first on the message's line.
if script --version 2>/dev/null | grep -q util-linux && command -v timeout >/dev/null 2>&1; then
  mkdir -p tty
  t0=$(now_ms)
  { ranks_running tty; printf '\003'
    # the terminal stays open until the launcher has ended (script(1) hangs up on its
    # job when its input ends: a loaded machine may take seconds to end the job)
    for _ in $(seq 1 300); do [ -n "$(ours "^[^ ]*lancer-mpirun .*-o tty/")" ] || break; sleep 0.1; done
    sleep 0.5; } | SHELL=/bin/bash timeout 60 script -qec \
    "lancer-mpirun ${opts[*]} -np 2 lancer-mpi render branching.rts -o tty/b.png --domains 1; echo \"status=\$?\"" \
    /dev/null >tty.log 2>&1
  t1=$(now_ms)
  if grep -aq '^status=130' tty.log && tr -d '\0' <tty.log | grep -aq '^\(\^C\)\?lancer-mpirun: interrupted'  \
     && ! grep -aq 'hit ctrl-c again' tty.log && [ -z "$(ls -A tty)" ]; then
    ok "Ctrl-C typed at a terminal: status 130, the message, mpirun signalled once"
  else fail "Ctrl-C at a terminal ($((t1 - t0)) ms):"; cat -v tty.log; fi
else fail "the terminal case: util-linux's script(1) is not installed (it is part of every Debian system)"; fi

[ "$failures" = 0 ] || { echo "$failures lancer-mpirun test(s) failed"; exit 1; }
echo "lancer-mpirun tests passed"
