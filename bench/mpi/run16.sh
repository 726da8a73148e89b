#!/usr/bin/env bash
# The 16-core run: lancer's domain curve and lancer-mpi's rank curve on one machine, as a
# table. Needs no OCaml: only bash, awk, Open MPI's mpirun, a statically linked `lancer`
# (LANCER_STATIC=1 dune build bin/static/lancer_static.exe) and `lancer-mpi` (built on
# Debian 13 it needs only Open MPI 5's libraries: apt-get install openmpi-bin; `make
# cluster-bundle` packs both with this script and the scenes it renders).
#
#   run16.sh                       # lancer and lancer-mpi next to this script, or on PATH
#   LANCER=/path/lancer LANCER_MPI=/path/lancer-mpi run16.sh
#
# For a still of the showcase (built into lancer) at W×H (default 1920×1080, preview) and
# the 48 frames 0..47 of bounce.rts at AW×AH (default 480×270):
#   * lancer with 1 … MAX domains (the domain curve; MAX defaults to the core count, at
#     most 16),
#   * lancer-mpi with 1 … MAX ranks of one domain each, rank 0 rendering too (the rank
#     curve), and 2 ranks × MAX/2 domains;
# each the median of REPEAT runs (default 3), with its speed-up over lancer on one domain
# and the efficiency (speed-up over the cores used; the target is 0.9). Every output is
# compared with lancer's on one domain, byte for byte. Knobs: CURVE (the counts, default
# "1 2 4 8 12 16" up to MAX), W, H, AW, AH, REPEAT, SCENE_DIR (where bounce.rts is),
# KINDS ("still anim"), MPIRUN_ARGS (extra mpirun options, e.g. --oversubscribe to try it
# on a smaller machine). Exit status 1 when an output differs or a run fails.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
find_cmd() { # NAME CANDIDATES...: the first executable candidate, else NAME on PATH
  local name=$1 c; shift
  for c in "$@"; do [ -x "$c" ] && { echo "$c"; return; }; done
  command -v "$name" || true
}
lancer=${LANCER:-$(find_cmd lancer "$here/lancer")}
lmpi=${LANCER_MPI:-$(find_cmd lancer-mpi "$here/lancer-mpi")}
[ -n "$lancer" ] || { echo "run16: no lancer (set LANCER=)"; exit 1; }
[ -n "$lmpi" ] || { echo "run16: no lancer-mpi (set LANCER_MPI=)"; exit 1; }
command -v mpirun >/dev/null 2>&1 || { echo "run16: mpirun is not installed (apt-get install openmpi-bin)"; exit 1; }
scene_dir=${SCENE_DIR:-}
if [ -z "$scene_dir" ]; then
  for d in "$here" "$here/../../scenes"; do [ -f "$d/bounce.rts" ] && { scene_dir=$d; break; }; done
fi
cores=$(nproc)
MAX=${MAX:-$((cores < 16 ? cores : 16))}
CURVE=${CURVE:-$(for k in 1 2 4 8 12 16; do [ "$k" -le "$MAX" ] && echo "$k"; done | tr '\n' ' ')}
W=${W:-1920}; H=${H:-1080}; AW=${AW:-480}; AH=${AH:-270}; REPEAT=${REPEAT:-3}; KINDS=${KINDS:-still anim}
half=$((MAX / 2 > 0 ? MAX / 2 : 1))
export OMPI_MCA_btl_base_warn_component_unused=0
read -r -a extra <<<"${MPIRUN_ARGS:-}"
mpirun=(mpirun --bind-to none "${extra[@]}")
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
failures=0

calc() { awk "BEGIN { printf \"%.6g\\n\", ($*) }"; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
timed() { # OUT CMD...: median seconds over REPEAT runs writing OUT; empty if a run failed
  local out=$1 t0 t1; shift
  : >"$tmp/t"
  for _ in $(seq "$REPEAT"); do
    rm -rf "$out"
    t0=$(date +%s%N)
    "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; return 0; }
    t1=$(date +%s%N)
    calc "($t1 - $t0) / 1e9" >>"$tmp/t"
  done
  median <"$tmp/t"
}
same() { # REF OUT: same bytes (a file, or every file of a directory)
  if [ -d "$1" ]; then local f; for f in "$1"/*; do [ -d "$f" ] || cmp -s "$f" "$2/$(basename "$f")" || return 1; done
  else cmp -s "$1" "$2"; fi
}

echo "lancer on $(uname -n): $cores cores, $(grep -m 1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2- | sed 's/^ //')"
echo "$(mpirun --version 2>/dev/null | head -n 1); median of $REPEAT runs; curve: $CURVE"
for kind in $KINDS; do
  if [ "$kind" = still ]; then
    ext=.png; title="A still: the showcase at ${W}×${H}, --quality preview"
    args=(render --width "$W" --height "$H" --quality preview -q)
  else
    [ -n "$scene_dir" ] || { echo "run16: bounce.rts not found (set SCENE_DIR=)"; exit 1; }
    ext=""; title="An animation: bounce.rts, 48 frames at ${AW}×${AH}"
    args=(animate "$scene_dir/bounce.rts" --frames 0..47 --width "$AW" --height "$AH" -q)
  fi
  ref=$tmp/ref$ext
  base=$(timed "$ref" "$lancer" "${args[@]}" -o "$ref" --domains 1)
  [ -n "$base" ] || { echo "run16: lancer failed"; exit 1; }
  echo
  echo "### $title"
  echo
  echo "| run | cores | seconds | speed-up | efficiency | same bytes |"
  echo "|---|---:|---:|---:|---:|---|"
  row() { # LABEL CORES OUT CMD...
    local label=$1 used=$2 out=$3 t ok; shift 3
    t=$(timed "$out" "$@")
    if [ -z "$t" ]; then echo "| $label | $used | failed |  |  |  |"; failures=$((failures + 1)); return; fi
    if same "$ref" "$out"; then ok=yes; else ok=NO; failures=$((failures + 1)); fi
    printf "| %s | %d | %.3f | %.2f× | %.2f | %s |\n" "$label" "$used" "$t" "$(calc "$base / $t")" "$(calc "$base / $t / $used")" "$ok"
  }
  printf "| lancer, 1 domain | 1 | %.3f | 1.00× | 1.00 | yes |\n" "$base"
  for k in $CURVE; do
    [ "$k" = 1 ] && continue
    row "lancer, $k domains" "$k" "$tmp/d$k$ext" "$lancer" "${args[@]}" -o "$tmp/d$k$ext" --domains "$k"
  done
  for k in $CURVE; do
    row "lancer-mpi, $k rank$([ "$k" = 1 ] || echo s) × 1 domain" "$k" "$tmp/r$k$ext" \
      "${mpirun[@]}" -np "$k" "$lmpi" "${args[@]}" -o "$tmp/r$k$ext" --domains 1
  done
  [ "$half" -gt 1 ] && row "lancer-mpi, 2 ranks × $half domains" $((2 * half)) "$tmp/s$ext" \
    "${mpirun[@]}" -np 2 "$lmpi" "${args[@]}" -o "$tmp/s$ext" --domains "$half"
done
[ "$failures" = 0 ] || { echo "run16: $failures run(s) failed or differed"; exit 1; }
