#!/usr/bin/env bash
# lancer-mpi against lancer under mpirun -np 1, 2 and 4: the bindings' own checks, then a
# still and an animation that must come out byte-identical (cmp), a scene error that is
# reported once with status 1 on every rank, and a failing worker that makes the job
# stop without writing the image. Skipped, with the reason, where Open MPI or the
# lancer commands are missing.
#
# usage: run.sh TEST_BINDINGS.exe SHOWCASE.rts ORBIT.rts [DEPTH_OF_FIELD.rts [MOTION_BLUR.rts]]
#   (lancer, lancer-mpi on PATH)
set -u
bindings=$(realpath "$1") showcase=$(realpath "$2") orbit=$(realpath "$3") dof=${4:+$(realpath "$4")}
blur=${5:+$(realpath "$5")}

# lancer-mpi was built, so an MPI library is installed: its mpirun must be too.
command -v mpirun >/dev/null 2>&1 ||
  { echo "FAIL: mpirun is not installed beside the MPI library lancer-mpi was built with (make deps installs openmpi-bin)"; exit 1; }

# Quiet and self-contained on one machine without a network: shared memory between
# ranks, no UCX, no warnings about unused transports. The user's settings win.
export OMPI_MCA_pml=${OMPI_MCA_pml:-ob1}
export OMPI_MCA_btl=${OMPI_MCA_btl:-self,sm}
export OMPI_MCA_btl_base_warn_component_unused=${OMPI_MCA_btl_base_warn_component_unused:-0}
mpirun=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }
# Messages about a job itself go to the test's output, whatever the caller redirects.
exec 3>&1
live_ranks() { ps -o stat= --ppid "$1" 2>/dev/null | grep -vc '^Z'; }
# supervised TRIES MPIRUN-ARGS...: one job under mpirun, limited to 60 s.
#   A rank still running at the limit is a hang of lancer-mpi: what each of its threads
#   waits on is printed, and the job fails with status 124.
#   Open MPI 5's launcher (prterun) is known to stay, now and then, after every rank of a
#   job has ended (PRRTE issue 1839, "mpirun/prte hang after application completion").
#   A job whose ranks have all ended 10 s ago while mpirun stays (or that has no rank at
#   the limit) is said to be such a job, ended, and run again while TRIES lasts (its
#   status and the files it wrote are then the next run's); else it fails with status
#   124.
supervised() {
  local tries=$1 pid t idle seen r th
  shift
  while :; do
    "${mpirun[@]}" "$@" &
    pid=$! t=0 idle=0 seen=0
    while kill -0 "$pid" 2>/dev/null && [ "$idle" -lt 100 ] && [ "$t" -lt 600 ]; do
      if [ "$(live_ranks "$pid")" -gt 0 ]; then idle=0 seen=1; elif [ "$seen" = 1 ]; then idle=$((idle + 1)); fi
      sleep 0.1
      t=$((t + 1))
    done
    if ! kill -0 "$pid" 2>/dev/null; then wait "$pid"; return; fi
    if [ "$(live_ranks "$pid")" = 0 ]; then
      tries=$((tries - 1))
      echo "note: mpirun stayed after every rank of the job had ended (Open MPI's launcher, not lancer-mpi); $([ "$tries" -gt 0 ] && echo "the job runs again" || echo "no tries left"): mpirun $*" | cut -c1-240 >&3
      kill -KILL "$pid" 2>/dev/null
      wait "$pid" 2>/dev/null
      [ "$tries" -gt 0 ] && continue
      return 124
    fi
    echo "a rank still runs after 60 s: mpirun $*" >&3
    for r in $(ps -o pid= --ppid "$pid"); do
      echo "  rank pid $r: $(tr '\0' ' ' <"/proc/$r/cmdline" 2>/dev/null | cut -c1-100)"
      for th in /proc/"$r"/task/*; do
        echo "    thread ${th##*/}: state $(awk '{print $3}' "$th/stat" 2>/dev/null), waits in $(cat "$th/wchan" 2>/dev/null)"
      done
    done >&3
    kill -TERM "$pid" 2>/dev/null
    sleep 2
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    return 124
  done
}
run() { supervised 2 "$@"; }
once() { supervised 1 "$@"; }

# The bindings.
for n in 1 2 4; do
  if run -np "$n" "$bindings" >bindings.log 2>&1; then ok "the bindings pass their checks on $n ranks"
  else fail "the bindings on $n ranks:"; cat bindings.log; fi
done

# The commands: lancer and lancer-mpi, both built with this tree.
if ! command -v lancer >/dev/null 2>&1 || ! lancer-mpi --help=plain >/dev/null 2>&1; then
  echo "FAIL: lancer or lancer-mpi is not on PATH"; exit 1
fi

# References from lancer itself.
lancer render "$showcase" --width 96 --height 72 -q -o ref.png >/dev/null || fail "lancer render"
lancer animate "$orbit" -o ref_frames -q >/dev/null || fail "lancer animate"

same_frames() { # DIR: every frame and the merged manifest equal the reference's
  for f in ref_frames/*.png ref_frames/lancer-frames.json; do cmp -s "$f" "$1/$(basename "$f")" || return 1; done
}

for n in 1 2 4; do
  if run -np "$n" lancer-mpi render "$showcase" --width 96 --height 72 -q -o "still$n.png" >/dev/null 2>still.log \
     && cmp -s ref.png "still$n.png"; then ok "a still on $n ranks is byte-identical to lancer render's"
  else fail "the still on $n ranks differs or failed"; cat still.log; fi
  if run -np "$n" lancer-mpi animate "$orbit" -o "frames$n" -q >/dev/null 2>anim.log && same_frames "frames$n"; then
    ok "an animation on $n ranks is byte-identical to lancer animate's, manifest included"
  else fail "the animation on $n ranks differs or failed"; cat anim.log; fi
done

# Depth of field: its lens points are a hash of frame, pixel and sample, whatever rank
# renders the tile.
if [ -n "$dof" ]; then
  lancer render "$dof" --width 48 --height 36 --samples 2 -q -o dof_ref.png >/dev/null || fail "lancer render (depth of field)"
  for n in 2 4; do
    if run -np "$n" lancer-mpi render "$dof" --width 48 --height 36 --samples 2 -q -o "dof$n.png" >/dev/null 2>dof.log \
       && cmp -s dof_ref.png "dof$n.png"; then ok "a depth-of-field still on $n ranks is byte-identical to lancer render's"
    else fail "the depth-of-field still on $n ranks differs or failed"; cat dof.log; fi
  done
fi

# Motion blur: each sample's instant is a hash of frame, pixel and sample, and every rank
# builds the same scenes at the shutter's instants.
if [ -n "$blur" ]; then
  lancer render "$blur" --width 48 --height 36 -q -o blur_ref.png >/dev/null || fail "lancer render (motion blur)"
  for n in 2 4; do
    if run -np "$n" lancer-mpi render "$blur" --width 48 --height 36 -q -o "blur$n.png" >/dev/null 2>blur.log \
       && cmp -s blur_ref.png "blur$n.png"; then ok "a motion-blurred still on $n ranks is byte-identical to lancer render's"
    else fail "the motion-blurred still on $n ranks differs or failed"; cat blur.log; fi
  done
fi

# Rank 0 renders units too while it serves: --stats says who rendered what, and every
# tile of the 96×72 still (3×3 tiles of 32×32) is accounted for exactly once.
for n in 2 4; do
  if run -np "$n" lancer-mpi render "$showcase" --width 96 --height 72 --domains 1 -q -o r0.png --stats r0.json \
       >/dev/null 2>r0.log; then
    flat=$(tr -s ' \n' ' ' <r0.json)
    units0=$(grep -o '"rank": 0, "units": [0-9]*' <<<"$flat" | grep -o '[0-9]*$')
    tiles=$(grep -o '"tiles": [0-9]*' <<<"$flat" | awk '{s += $2} END {print s}')
    ranks=$(grep -o '"rank": [0-9]*' <<<"$flat" | wc -l)
    if [ "${units0:-0}" -ge 1 ] && [ "$tiles" = 9 ] && [ "$ranks" = "$n" ] && grep -q '"reply_wait_ms"' r0.json; then
      ok "on $n ranks rank 0 renders units too ($units0 of them) and all 9 tiles are counted once"
    else fail "rank 0's units on $n ranks: units0=${units0:-none} tiles=$tiles ranks=$ranks"; cat r0.json; fi
  else fail "the still with --stats on $n ranks"; cat r0.log; fi
done

# Ctrl-C reaching rank 0 while its own domains render and it serves: the job ends with
# status 130 and no image (the render would take far longer than the test waits).
here=$(pwd -P)
for d in 1 2 resume; do
  rm -f int.png int.png.checkpoint
  extra=()
  [ "$d" = resume ] && { d=1; extra=(--resume); }
  # The ranks of the previous job may still be exiting after its mpirun returned: none of
  # them is taken for this job's rank 0 (an interrupt sent to one would leave this job
  # rendering to the end, past the timeout).
  before=" $(pgrep -x lancer-mpi | tr '\n' ' ') "
  once -np 2 lancer-mpi render "$showcase" --width 1920 --height 1080 --samples 4 --domains "$d" -q -o int.png \
    "${extra[@]}" >/dev/null 2>int.log &
  job=$!
  rank0=
  # This job's rank 0 only: the one in this test's own directory (other jobs, and the
  # previous one still exiting, may have a rank 0 too).
  for _ in $(seq 300); do
    for p in $(pgrep -x lancer-mpi); do
      case "$before" in *" $p "*) continue ;; esac
      [ "$(readlink "/proc/$p/cwd" 2>/dev/null)" = "$here" ] || continue
      [ "$(cat "/proc/$p/stat" 2>/dev/null | awk '{print $3}')" = Z ] && continue
      tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=0' || continue
      # Once it catches SIGINT (SigCgt bit 1): on a loaded machine a process may not have
      # started its runtime yet a second after it was found, and would die of the signal.
      cgt=$(awk '/^SigCgt:/ {print $2}' "/proc/$p/status" 2>/dev/null)
      [ -n "$cgt" ] && [ $(( 0x$cgt & 2 )) -ne 0 ] && rank0=$p
    done
    [ -n "$rank0" ] && break
    sleep 0.1
  done
  sleep 1
  [ -n "$rank0" ] && kill -INT "$rank0"
  wait "$job"
  status=$?
  if [ -n "$rank0" ] && [ "$status" = 130 ] && [ ! -e int.png ] && grep -q "interrupted" int.log; then
    ok "an interrupt on rank 0 with $d domain(s) ends the job with status 130 and no image"
  else fail "interrupt with $d domain(s): rank 0 pid ${rank0:-not found}, status $status"; cat int.log; fi
  # With --resume the finished tiles stay in the checkpoint, and the message says so.
  if [ ${#extra[@]} -gt 0 ]; then
    if [ -e int.png.checkpoint ] && grep -q "kept in the checkpoint; run again with --resume" int.log; then
      ok "an interrupted --resume keeps the checkpoint and says so"
    else fail "interrupted --resume: checkpoint $(ls int.png.checkpoint 2>&1)"; cat int.log; fi
    rm -f int.png.checkpoint
  fi
done

# Fewer frames than ranks: frames are cut into tiles; one domain per rank.
if run -np 4 lancer-mpi animate "$orbit" -o frames_tiles --frames 2..3 --domains 1 -q >/dev/null 2>anim.log \
   && cmp -s ref_frames/frame_0002.png frames_tiles/frame_0002.png && cmp -s ref_frames/frame_0003.png frames_tiles/frame_0003.png; then
  ok "two frames cut into tiles over 3 workers are byte-identical"
else fail "frames in tiles differ or failed"; cat anim.log; fi

# Resume: lancer-mpi skips what lancer wrote.
if run -np 2 lancer-mpi animate "$orbit" -o ref_frames --resume >resume.log 2>&1 && grep -q "6 frames already rendered, 0 to go" resume.log; then
  ok "lancer-mpi --resume recognises the frames lancer animate wrote"
else fail "resume"; cat resume.log; fi

# A still stopped midway (the job killed) and resumed: rank 0 keeps the checkpoint, and the
# image is the same bytes as an uninterrupted one.
# The image is large enough (about 3 s of work on two workers) that the job is still
# running when the poll below sees its first checkpoint, even on a loaded machine.
lancer render "$showcase" --width 960 --height 720 -q -o ref960.png >/dev/null || fail "lancer render 960"
still=(lancer-mpi render "$showcase" --width 960 --height 720 --domains 1 --resume -o resumed.png)
"${mpirun[@]}" -np 3 "${still[@]}" -q >/dev/null 2>killed.log &
pid=$!
for _ in $(seq 3000); do [ -e resumed.png.checkpoint ] && break; sleep 0.02; done
kill -TERM "$pid" 2>/dev/null || echo "the job had ended before it could be killed" >>killed.log
wait "$pid" 2>/dev/null
if [ -e resumed.png.checkpoint ] && [ ! -e resumed.png ] \
   && once -np 3 "${still[@]}" >resumed.log 2>&1 && grep -q "tiles already rendered" resumed.log \
   && cmp -s ref960.png resumed.png && [ ! -e resumed.png.checkpoint ]; then
  ok "a still killed midway on 3 ranks and resumed is byte-identical, and its checkpoint is removed"
else fail "the resumed still on 3 ranks"; cat killed.log; [ -e resumed.log ] && cat resumed.log; fi

# A scene error: one message, from rank 0, and status 1.
printf 'sphere { center: (0, 1, 0) }\n' >bad.rts
run -np 3 lancer-mpi render bad.rts -o bad.png >bad.out 2>bad.err
status=$?
count=$(grep -c 'needs a `radius` field' bad.err)
if [ "$status" = 1 ] && [ "$count" = 1 ] && [ ! -e bad.png ]; then ok "a scene error is reported once and the job exits with status 1"
else fail "scene error: status $status, $count messages"; cat bad.err; fi

# The other ranks take the scene and its includes from rank 0, never from their own disk:
# an include edited while a job starts (here: another version of it where the other
# ranks run, as on a node that sees the file change a moment later) cannot make one
# image of two versions. The image is the one rank 0's files give.
mkdir -p inc elsewhere/inc
printf 'sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }\n' >inc/part.rts
printf 'sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.2, 0.2, 0.9) } }\n' >elsewhere/inc/part.rts
printf 'settings { width: 256, height: 192, samples: 2 }\ncamera { position: (0, 1, -5), look_at: (0, 1, 0) }\ninclude "inc/part.rts"\nlight { position: (0, 5, -5) }\n' >withinc.rts
cp withinc.rts elsewhere/withinc.rts
lancer render withinc.rts -o inc_ref.png -q >/dev/null 2>&1 || fail "lancer render withinc.rts"
run -np 3 bash -c '[ "$OMPI_COMM_WORLD_RANK" = 0 ] || cd elsewhere; exec lancer-mpi render withinc.rts -o inc.png -q --domains 1' \
  >inc.out 2>inc.err
status=$?
if [ "$status" = 0 ] && cmp -s inc_ref.png inc.png; then ok "the other ranks render rank 0's includes, not the versions on their own disk"
else fail "an include that differs on the other ranks: status $status"; cat inc.err; fi

# Images and meshes are read by every rank, and each unit comes back with their digests:
# pixels made of another version of a texture than rank 0's are refused, with a message
# and no image. The image is large enough that rank 1 renders a unit before rank 0's own
# worker has rendered every tile: at 256×192 rank 0 sometimes rendered them all before
# rank 1 asked for one, and the job then rightly ended with rank 0's image.
printf 'P6\n1 1\n255\n\310\40\40' >tex.ppm
printf 'P6\n1 1\n255\n\40\40\310' >elsewhere/tex.ppm
printf 'settings { width: 1024, height: 768, samples: 3 }\nlight { position: (0, 5, -5) }\nsphere { center: (0, 0, 0), radius: 1, material: material { texture: image("tex.ppm", 1) } }\n' >withtex.rts
cp withtex.rts elsewhere/withtex.rts
run -np 2 bash -c '[ "$OMPI_COMM_WORLD_RANK" = 0 ] || cd elsewhere; exec lancer-mpi render withtex.rts -o tex.png -q --domains 1' \
  >tex.out 2>tex.err
status=$?
if [ "$status" = 1 ] && grep -q "rank 1: it read tex.ppm with other contents than rank 0 did" tex.err && [ ! -e tex.png ]; then
  ok "a texture that differs on another rank stops the job with a message and no image"
else fail "a texture that differs on another rank: status $status"; cat tex.err; fi

# A worker that cannot do its part stops the job with a clear message and no image: here
# the scene's texture is one that only rank 0 can see (the others run in a directory
# without it, as on a node of a cluster without the file).
mkdir -p bare
cp withtex.rts bare/withtex.rts
run -np 2 bash -c '[ "$OMPI_COMM_WORLD_RANK" = 0 ] || cd bare; exec lancer-mpi render withtex.rts -o bare.png -q' \
  >bare.out 2>bare.err
status=$?
if [ "$status" = 1 ] && grep -q "rank 1: " bare.err && [ ! -e bare.png ]; then ok "a worker's failure stops the job with a message and no image"
else fail "worker failure: status $status"; cat bare.err; fi
# The 16-core run's script, at a tiny size on 1 and 2 ranks: it finds the commands, prints
# the table and checks every output against lancer's.
if LANCER=$(command -v lancer) LANCER_MPI=$(command -v lancer-mpi) SCENE_DIR=$(dirname "$showcase") CURVE="1 2" MAX=2 \
     KINDS="still anim" W=48 H=32 AW=16 AH=9 REPEAT=1 MPIRUN_ARGS=--oversubscribe timeout 120 bash "$(dirname "$bindings")/../../bench/mpi/run16.sh" >run16.out 2>&1 \
   && grep -q '^| lancer-mpi, 2 ranks × 1 domain | 2 | [0-9.]* | [0-9.]*× | [0-9.]* | yes |$' run16.out \
   && grep -q '^| lancer, 2 domains | 2 |' run16.out; then
  ok "run16.sh prints the domain and rank curves, every output the same bytes"
else fail "run16.sh"; cat run16.out; fi

# Stopping a job. The scene never finishes on its own in reasonable time: three
# half-mirror, half-glass planes double a sample's rays at every bounce.
cat >branching.rts <<'EOS'
settings { width: 64, height: 48, depth: 1000 }
camera { position: (0, 0, -0.5), look_at: (1, 0.3, 0) }
light { position: (0, 5, -0.5) }
let m = material { reflection: 0.5, transparency: 0.5, ior: 1 }
plane { normal: (0, 0, 1), offset: -1, material: m }
plane { normal: (0, 0, 1), offset: 0, material: m }
plane { normal: (0, 0, 1), offset: 1, material: m }
EOS
rank_pid() { # OUTPUT RANK: the pid of that rank of the job writing OUTPUT, once it runs
  # (in this test's directory: the same test run elsewhere at once has such ranks too)
  local i p
  for i in $(seq 1 600); do
    for p in $(pgrep -f -- "-o $1"); do
      [ "$(cat /proc/"$p"/comm 2>/dev/null)" = lancer-mpi ] || continue
      [ "$(readlink "/proc/$p/cwd" 2>/dev/null)" = "$here" ] || continue
      tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$2" && { echo "$p"; return; }
    done
    sleep 0.05
  done
}

# Waits (30 s at most) for the job's first tiles line in its stderr FILE, then 0.5 s:
# the job is rendering (on a loaded machine a job may take seconds to start).
rendering() {
  local i
  for i in $(seq 1 600); do grep -aq '^tiles ' "$1" && break; sleep 0.05; done
  sleep 0.5
}

# Ctrl-C reaches the ranks (the terminal signals its whole foreground group): one rank
# rendering on two domains stops at once, exit 130, no image.
mkdir -p stop1
"${mpirun[@]}" -np 1 lancer-mpi render branching.rts -o stop1/b.png --domains 2 --progress >stop1.out 2>stop1.err &
job=$!
r=$(rank_pid stop1/b.png 0)
rendering stop1.err
[ -n "$r" ] && kill -INT "$r"
for i in $(seq 1 100); do kill -0 "$job" 2>/dev/null || break; sleep 0.05; done
if kill -0 "$job" 2>/dev/null; then
  fail "Ctrl-C on one rank with two domains: still running 5 s later"; kill -9 "$job"; pkill -9 -P "$job"
fi
wait "$job"; status=$?
if [ "$status" = 130 ] && grep -q "interrupted; no output was written" stop1.err && [ -z "$(ls -A stop1)" ]; then
  ok "Ctrl-C stops one rank rendering on two domains within 5 s: exit 130, no image"
else fail "Ctrl-C on one rank: status $status, files: $(ls -A stop1)"; cat stop1.err; fi

# A worker killed with kill -9: mpirun stops rank 0 with SIGTERM, and rank 0 does not
# call that an interruption by the user.
mkdir -p stop2
"${mpirun[@]}" -np 2 lancer-mpi render branching.rts -o stop2/b.png --domains 1 --progress >stop2.out 2>stop2.err &
job=$!
w=$(rank_pid stop2/b.png 1)
rendering stop2.err
[ -n "$w" ] && kill -9 "$w"
for i in $(seq 1 200); do kill -0 "$job" 2>/dev/null || break; sleep 0.05; done
kill -0 "$job" 2>/dev/null && { kill -9 "$job"; pkill -9 -P "$job"; }
wait "$job"; status=$?
if [ "$status" != 0 ] && grep -q "another rank has died" stop2.err && ! grep -q "interrupted" stop2.err && [ -z "$(ls -A stop2)" ]; then
  ok "a worker killed with kill -9 ends the job, reported as such, with no image (status $status)"
else fail "a killed worker: status $status, files: $(ls -A stop2)"; cat stop2.err; fi

# A worker killed while rank 0 writes the finished image. (The scene renders at once and
# its 9 M pixels take seconds to compress; the progress line "writing …" comes once the
# job is over and the write has begun.) The workers leave the job before the write: one
# that has left costs nothing, and the image is kept. One still exiting when it is killed
# (a loaded machine) makes mpirun stop rank 0, which then leaves nothing: no image, no
# temporary file, whatever mpirun's timing.
printf 'settings { width: 3000, height: 3000, background: (0.2, 0.4, 0.6) }\n' >plain.rts
mkdir -p stop3
"${mpirun[@]}" -np 2 lancer-mpi render plain.rts -o stop3/p.png --domains 1 --progress >stop3.out 2>stop3.err &
job=$!
w=$(rank_pid stop3/p.png 1)
for i in $(seq 1 1200); do grep -aq '^writing stop3/p.png' stop3.err && break; kill -0 "$job" 2>/dev/null || break; sleep 0.05; done
writing=no; kill -0 "$job" 2>/dev/null && [ ! -e stop3/p.png ] && writing=yes
alive=no; [ -n "$w" ] && kill -9 "$w" 2>/dev/null && alive=yes
wait "$job"; status=$?
# Decided by what is on disk and what is said, not by mpirun's status, which depends on
# whether the killed worker had left the job when mpirun noticed (0 or 137).
mkdir -p ref3 # the same depth: an image's record names its scene from its directory
lancer render plain.rts -o ref3/p.png -q >/dev/null 2>&1 || fail "lancer render plain.rts"
files=$(ls -A stop3)
if [ "$writing" != yes ]; then
  fail "a worker killed during the write: the write was not under way (status $status, files: $files)"; cat stop3.err
elif [ "$files" = p.png ] && cmp -s ref3/p.png stop3/p.png && ! grep -q '^lancer: ' stop3.err; then
  ok "a worker killed while rank 0 writes the image (still running: $alive): the image is kept, complete"
elif [ "$alive" = yes ] && [ -z "$files" ] && grep -q 'process rank 1' stop3.err \
     && ! grep -q 'interrupted' stop3.err; then
  ok "a worker killed before it left the job, while rank 0 writes: mpirun names it and stops the job, nothing half-written is left"
else fail "a worker killed during the write (still running: $alive): status $status, files: $files"; cat stop3.err; fi

[ "$failures" = 0 ] || { echo "$failures MPI test(s) failed"; exit 1; }
echo "MPI tests passed"
