#!/usr/bin/env bash
# lancer-mpi's scaling model (make bench-mpi), for a still of the showcase at W×H
# (default 1920×1080, preview quality) and the 48-frame bounce animation (frames 0..47 of
# scenes/bounce.rts at AW×AH, default 480×270).
#
# 1. It measures what the model needs, on this machine: the render time per pixel on one
#    domain, a frame's scene evaluation and write, the fixed cost of a job (mpirun,
#    start-up, evaluating the scene: lancer-mpi on a 32×32 image) for 1 to 8 ranks, and
#    rank 0's serving rate with units that render nothing (bench/mpi/serve_rate.exe,
#    under mpirun -np 2..8 --oversubscribe) for units of one tile, of a still's chunk and
#    of a whole frame, which gives its cost per unit and per byte.
# 2. It runs lancer-mpi here (1 and 2 ranks, and more ranks or domains than cores) and
#    prints each time next to the model's prediction (bench/mpi/model.exe says how it
#    predicts), for as many cores as lancer's own speed-up on every core shows this
#    machine gives (on a shared machine, other jobs take some).
# 3. It predicts 16, 64, 256 and 1024 ranks of 1 and of 16 domains, where rank 0's link
#    carries LINK_GBPS Gbit/s (default 10) and starting the job costs the fixed cost of
#    one rank plus, per doubling of the ranks, what the second rank cost here; and says
#    what bounds each.
# Times are the median of REPEAT runs (default 3). Knobs: W, H, AW, AH, REPEAT,
# LINK_GBPS, LANCER, LANCER_MPI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
command -v mpirun >/dev/null 2>&1 || { echo "bench-mpi: mpirun is not installed (apt-get install openmpi-bin libopenmpi-dev)"; exit 1; }
dune build @install ./bench/mpi/serve_rate.exe ./bench/mpi/model.exe 2>&1 | tail -n 5
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}
lmpi=${LANCER_MPI:-"$root/_build/default/bin/mpi/lancer_mpi_main.exe"}
rate=$root/_build/default/bench/mpi/serve_rate.exe
model=$root/_build/default/bench/mpi/model.exe
W=${W:-1920}; H=${H:-1080}; AW=${AW:-480}; AH=${AH:-270}; REPEAT=${REPEAT:-3}; LINK_GBPS=${LINK_GBPS:-10}
cores=$(nproc)
export OMPI_MCA_pml=${OMPI_MCA_pml:-ob1} OMPI_MCA_btl=${OMPI_MCA_btl:-self,sm}
export OMPI_MCA_btl_base_warn_component_unused=0
mpirun=(mpirun --oversubscribe --bind-to none)
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
calc() { awk "BEGIN { printf \"%.6g\\n\", ($*) }"; }

# Seconds of one run of CMD, its output kept in $tmp/out.txt.
secs() {
  local t0 t1
  t0=$(date +%s%N)
  "$@" >"$tmp/out.txt" 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }
  t1=$(date +%s%N)
  calc "($t1 - $t0) / 1e9"
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
timed() { # CMD...: median seconds over REPEAT runs
  : >"$tmp/t"
  for _ in $(seq "$REPEAT"); do rm -rf "$tmp/o" "$tmp/o.png"; secs "$@" >>"$tmp/t"; done
  median <"$tmp/t"
}
field() { tr -s ' \n' ' ' <"$1" | grep -o "\"$2\": [0-9.e+-]*" | head -n 1 | awk '{print $2}'; }
word() { awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}'; } # value after KEY on stdin

still=(render scenes/showcase.rts -o "$tmp/o.png" --width "$W" --height "$H" --quality preview -q)
anim=(animate scenes/bounce.rts -o "$tmp/o" --frames 0..47 --width "$AW" --height "$AH" -q)

echo "lancer-mpi's scaling model, measured on $cores cores, median of $REPEAT runs ($(mpirun --version | head -n 1))"

# ---- 1. What the model needs ----
# The still: render time per pixel (lancer's own wall time excludes start-up and write),
# and the write, from the whole command's time less a 32×32 render's.
small_still=$(timed "$lancer" render scenes/showcase.rts -o "$tmp/o.png" --width 32 --height 32 -q)
: >"$tmp/r"; : >"$tmp/t"
for _ in $(seq "$REPEAT"); do
  secs "$lancer" "${still[@]}" --domains 1 --stats "$tmp/s.json" >>"$tmp/t"
  field "$tmp/s.json" wall_seconds >>"$tmp/r"
done
x_still=$(median <"$tmp/t"); r_still=$(median <"$tmp/r")
# The cores this machine gives us now (others' jobs may take some): lancer's speed-up on
# every core, at most the core count. The runs here are predicted with it.
x_all=$(timed "$lancer" "${still[@]}" --domains "$cores")
eff=$(calc "$x_still / $x_all < 1 ? 1 : ($x_still / $x_all < $cores ? $x_still / $x_all : $cores)")
pixel_still=$(calc "$r_still / ($W * $H)")
write_still=$(calc "($x_still - $r_still - $small_still) > 0 ? $x_still - $r_still - $small_still : 0")
# The animation: a frame's evaluation from 48 frames at 8×8, its write from one frame at
# AW×AH, the time per pixel from the rest.
small_anim=$(timed "$lancer" render scenes/bounce.rts -o "$tmp/o.png" --width 8 --height 8 -q)
x_anim_small=$(timed "$lancer" animate scenes/bounce.rts -o "$tmp/o" --frames 0..47 --width 8 --height 8 -q --domains 1)
eval_anim=$(calc "($x_anim_small - $small_anim) / 48 > 0 ? ($x_anim_small - $small_anim) / 48 : 0")
: >"$tmp/r"; : >"$tmp/t"
for _ in $(seq "$REPEAT"); do
  secs "$lancer" render scenes/bounce.rts -o "$tmp/o.png" --width "$AW" --height "$AH" --domains 1 -q --stats "$tmp/s.json" >>"$tmp/t"
  field "$tmp/s.json" wall_seconds >>"$tmp/r"
done
write_anim=$(calc "$(median <"$tmp/t") - $(median <"$tmp/r") - $small_anim")
write_anim=$(calc "$write_anim > 0 ? $write_anim : 0")
x_anim=$(timed "$lancer" "${anim[@]}" --domains 1)
pixel_anim=$(calc "($x_anim - $small_anim - 48 * ($eval_anim + $write_anim)) / (48 * $AW * $AH)")

# The fixed cost of a job of N ranks.
declare -A fixed
for n in 1 2 4 8; do
  fixed[$n]=$(timed "${mpirun[@]}" -np "$n" "$lmpi" render scenes/showcase.rts -o "$tmp/o.png" --width 32 --height 32 --domains 1 -q)
done
doubling=$(calc "${fixed[2]} > ${fixed[1]} ? ${fixed[2]} - ${fixed[1]} : 0")

# Rank 0's serving rate with empty units.
echo
echo "### Rank 0's serving rate, units that render nothing (bench/mpi/serve_rate.exe)"
echo
echo "| units | bytes per unit | ranks | units | seconds | units/s | MB/s into rank 0 | median wait (ms) |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|"
best() { sort -g | tail -n 1; }
: >"$tmp/tile"; : >"$tmp/chunk"; : >"$tmp/frame"
for n in 2 4 8; do
  for kind in tile chunk frame; do
    case $kind in
      tile) args=(32 32 $((100 * n))) ;;
      chunk) args=("$W" "$H" 1) ;;
      frame) args=("$AW" "$AH" 48) ;;
    esac
    : >"$tmp/rates"
    for _ in $(seq "$REPEAT"); do timeout 120 "${mpirun[@]}" -np "$n" "$rate" "${args[@]}" >"$tmp/line"; cat "$tmp/line" >>"$tmp/rates"; done
    line=$(sort -g -k 14 "$tmp/rates" | awk -v m=$(((REPEAT + 1) / 2)) 'NR == m')
    units=$(word units <<<"$line"); bytes=$(word bytes_per_unit <<<"$line"); s=$(word seconds <<<"$line")
    ups=$(word units_per_s <<<"$line"); wait=$(word median_wait_ms <<<"$line")
    printf "| %s | %d | %d | %d | %.3f | %.0f | %.0f | %.3f |\n" "$kind" "$bytes" "$n" "$units" "$s" "$ups" "$(calc "$ups * $bytes / 1e6")" "$wait"
    echo "$ups $bytes" >>"$tmp/$kind"
  done
done
# Cost per unit and per byte from the fastest rate of one-tile and whole-frame units.
read -r r1 b1 < <(sort -g "$tmp/tile" | tail -n 1)
read -r r2 b2 < <(sort -g "$tmp/frame" | tail -n 1)
per_byte=$(calc "(1 / $r2 - 1 / $r1) / ($b2 - $b1) > 0 ? (1 / $r2 - 1 / $r1) / ($b2 - $b1) : 0")
per_unit=$(calc "1 / $r1 - $b1 * $per_byte > 0 ? 1 / $r1 - $b1 * $per_byte : 0")

echo
echo "### What the model is built from"
echo
echo "| figure | value |"
echo "|---|---:|"
printf "| cores this machine gave (lancer's speed-up on %d domains) | %.2f |\n" "$cores" "$eff"
printf "| still: render time per pixel, one domain | %.3f µs |\n" "$(calc "$pixel_still * 1e6")"
printf "| still: one 32×32 tile, one domain | %.2f ms |\n" "$(calc "$pixel_still * 1024 * 1e3")"
printf "| still: writing the %d×%d PNG | %.3f s |\n" "$W" "$H" "$write_still"
printf "| animation: render time per pixel, one domain | %.3f µs |\n" "$(calc "$pixel_anim * 1e6")"
printf "| animation: a frame's scene evaluation | %.2f ms |\n" "$(calc "$eval_anim * 1e3")"
printf "| animation: writing a %d×%d frame | %.2f ms |\n" "$AW" "$AH" "$(calc "$write_anim * 1e3")"
for n in 1 2 4 8; do printf "| fixed cost of a job (32×32 still), %d rank%s | %.3f s |\n" "$n" "$([ $n = 1 ] || echo s)" "${fixed[$n]}"; done
printf "| rank 0's serving: per unit | %.1f µs |\n" "$(calc "$per_unit * 1e6")"
printf "| rank 0's serving: per byte handed in | %.3f ns (%.2f GB/s) |\n" "$(calc "$per_byte * 1e9")" "$(calc "$per_byte > 0 ? 1e-9 / $per_byte : 0")"
printf "| bytes per tile (32×32 pixels, 3 doubles each) | %d |\n" 24576

predict() { # KIND N D CORES LINK FIXED: the model's line
  local kind=$1 n=$2 d=$3 c=$4 link=$5 fx=$6
  if [ "$kind" = still ]; then
    "$model" width="$W" height="$H" frames=1 ranks="$n" domains="$d" cores="$c" pixel="$pixel_still" eval=0 \
      write="$write_still" unit="$per_unit" byte="$per_byte" link_gbps="$link" fixed="$fx"
  else
    "$model" width="$AW" height="$AH" frames=48 ranks="$n" domains="$d" cores="$c" pixel="$pixel_anim" eval="$eval_anim" \
      write="$write_anim" unit="$per_unit" byte="$per_byte" link_gbps="$link" fixed="$fx"
  fi
}

# ---- 2. The model against lancer-mpi here ----
for kind in still anim; do
  if [ "$kind" = still ]; then
    args=("${still[@]}"); base=$x_still
    echo; echo "### The model against lancer-mpi here: scenes/showcase.rts at ${W}×${H}, --quality preview"
  else
    args=("${anim[@]}"); base=$x_anim
    echo; echo "### The model against lancer-mpi here: scenes/bounce.rts, 48 frames at ${AW}×${AH}"
  fi
  echo
  echo "| run | domains in all | measured s | predicted s | error | measured speed-up | predicted speed-up |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
  printf "| lancer, 1 domain | 1 | %.2f |  |  | 1.00× |  |\n" "$base"
  for nd in 1x1 2x1 1x2 2x2 4x1 8x1; do
    n=${nd%x*} d=${nd#*x}
    t=$(timed "${mpirun[@]}" -np "$n" "$lmpi" "${args[@]}" --domains "$d")
    fx=${fixed[$n]}
    p=$(predict "$kind" "$n" "$d" "$eff" 0 "$fx" | word seconds)
    over=""; [ $((n * d)) -gt "$cores" ] && over=" (over $cores cores)"
    printf "| lancer-mpi -np %d × %d domain%s%s | %d | %.2f | %.2f | %+.0f%% | %.2f× | %.2f× |\n" "$n" "$d" "$([ "$d" = 1 ] || echo s)" "$over" \
      $((n * d)) "$t" "$p" "$(calc "100 * ($p / $t - 1)")" "$(calc "$base / $t")" "$(calc "$base / $p")"
  done
done

# ---- 3. Predictions ----
echo
echo "### Predicted on a cluster: rank 0's link ${LINK_GBPS} Gbit/s, one core per domain"
echo
echo "Speed-up against lancer on one domain; efficiency is the speed-up over the domains in all."
echo "\"after start-up\" leaves out the fixed cost of starting the job (mpirun, evaluating the scene)."
echo
echo "| job | ranks × domains | predicted s | speed-up | efficiency | efficiency after start-up | units | bound |"
echo "|---|---|---:|---:|---:|---:|---:|---|"
for kind in still anim; do
  if [ "$kind" = still ]; then base=$x_still name="still ${W}×${H}"; else base=$x_anim name="48 frames ${AW}×${AH}"; fi
  for d in 1 16; do
    for n in 16 64 256 1024; do
      fx=$(calc "${fixed[1]} + $doubling * log($n) / log(2)")
      line=$(predict "$kind" "$n" "$d" $((n * d)) "$LINK_GBPS" "$fx")
      p=$(word seconds <<<"$line")
      sp=$(calc "$base / $p")
      after=$(calc "($base - ${fixed[1]}) / ($p - $fx) / ($n * $d)")
      printf "| %s | %d × %d | %.3f | %.1f× | %.2f | %.2f | %d | %s |\n" "$name" "$n" "$d" "$p" "$sp" "$(calc "$sp / ($n * $d)")" "$after" \
        "$(word units <<<"$line")" "$(word bound <<<"$line" | tr _ ' ')"
    done
  done
done

# Where it stops scaling: for each job and domains per rank, the most ranks (doubling
# from 1) predicted at 0.9 of the ideal speed-up over one rank of as many domains, fixed
# cost included, and what costs most besides the rendering at the next doubling.
echo
echo "### Where the scheme stops scaling (predicted: 0.9 of the ideal speed-up over one rank)"
echo
for kind in still anim; do
  if [ "$kind" = still ]; then base=$x_still name="still ${W}×${H}"; else base=$x_anim name="48 frames ${AW}×${AH}"; fi
  for d in 1 16; do
    last=1 why=""
    one=$(predict "$kind" 1 "$d" "$d" "$LINK_GBPS" "${fixed[1]}" | word seconds)
    for n in 2 4 8 16 32 64 128 256 512 1024; do
      fx=$(calc "${fixed[1]} + $doubling * log($n) / log(2)")
      line=$(predict "$kind" "$n" "$d" $((n * d)) "$LINK_GBPS" "$fx")
      ok=$(calc "$one / $(word seconds <<<"$line") / $n >= 0.9 ? 1 : 0")
      if [ "$ok" = 1 ]; then last=$n; else why=$(word limit <<<"$line" | tr _ ' '); break; fi
    done
    per="$d domain$([ "$d" = 1 ] || echo s) per rank"
    if [ -n "$why" ]; then echo "* $name, $per: up to $last rank$([ "$last" = 1 ] || echo s); at $((last * 2)) what costs most besides rendering is $why."
    else echo "* $name, $per: up to 1024 ranks and beyond."; fi
  done
done
