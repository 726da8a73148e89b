#!/usr/bin/env bash
# lancer-mpi against lancer on this machine (make bench-mpi): a still of the showcase at
# W×H (default 1920×1080, preview quality) and the 48-frame bounce animation (scenes/bounce.rts, frames
# 0..47 at AW×AH, default 480×270), median of REPEAT runs (default 3). Rows: lancer with
# 1 domain and with every core; lancer-mpi with 1 rank (it renders alone), and with
# 1 + N worker ranks of one domain each for N = 1 … cores (rank 0 only serves), and
# 1 + 1 worker with every core as domains. The speed-up is against lancer on 1 domain;
# "MPI overhead" compares each lancer-mpi row with lancer using the same number of
# rendering cores. mpirun's own start-up (about 1.5 s with Open MPI 6) is included, as a
# user sees it. Knobs: W, H, AW, AH, REPEAT, LANCER, LANCER_MPI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
command -v mpirun >/dev/null 2>&1 || { echo "bench-mpi: mpirun is not installed (apt-get install openmpi-bin libopenmpi-dev)"; exit 1; }
dune build @install 2>&1 | tail -n 5
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}
lmpi=${LANCER_MPI:-"$root/_build/default/bin/mpi/lancer_mpi_main.exe"}
W=${W:-1920}; H=${H:-1080}; AW=${AW:-480}; AH=${AH:-270}; REPEAT=${REPEAT:-3}
cores=$(nproc)
export OMPI_MCA_pml=${OMPI_MCA_pml:-ob1} OMPI_MCA_btl=${OMPI_MCA_btl:-self,sm}
export OMPI_MCA_btl_base_warn_component_unused=0
mpirun=(mpirun --oversubscribe --bind-to none)
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

secs() { local t0 t1; t0=$(date +%s.%N); "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }; t1=$(date +%s.%N); echo "$t1 - $t0" | bc -l; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
run() { # LABEL CORES CMD...: median seconds over REPEAT runs
  local label=$1 used=$2; shift 2
  : >"$tmp/t"
  for _ in $(seq "$REPEAT"); do rm -rf "$tmp/out"; secs "$@" >>"$tmp/t"; done
  echo "$label|$used|$(median <"$tmp/t")"
}

bench() { # KIND: still or animation
  local kind=$1 args
  if [ "$kind" = still ]; then
    args=(render scenes/showcase.rts -o "$tmp/out.png" --width "$W" --height "$H" --quality preview -q)
  else
    args=(animate scenes/bounce.rts -o "$tmp/out" --frames 0..47 --width "$AW" --height "$AH" -q)
  fi
  {
    run "lancer, 1 domain" 1 "$lancer" "${args[@]}" --domains 1
    run "lancer, $cores domains" "$cores" "$lancer" "${args[@]}" --domains "$cores"
    run "lancer-mpi -np 1, 1 domain" 1 "${mpirun[@]}" -np 1 "$lmpi" "${args[@]}" --domains 1
    for n in $(seq 1 "$cores"); do
      w=workers; [ "$n" = 1 ] && w=worker
      run "lancer-mpi -np $((n + 1)): $n $w × 1 domain" "$n" "${mpirun[@]}" -np $((n + 1)) "$lmpi" "${args[@]}" --domains 1
    done
    run "lancer-mpi -np 2: 1 worker × $cores domains" "$cores" "${mpirun[@]}" -np 2 "$lmpi" "${args[@]}" --domains "$cores"
  } >"$tmp/rows"
  local base; base=$(head -n 1 "$tmp/rows" | cut -d'|' -f3)
  echo
  if [ "$kind" = still ]; then echo "### A still: scenes/showcase.rts at ${W}×${H}, --quality preview"; else echo "### An animation: scenes/bounce.rts, 48 frames at ${AW}×${AH}"; fi
  echo
  echo "| run | rendering cores | seconds | speed-up | MPI overhead |"
  echo "|---|---:|---:|---:|---:|"
  while IFS='|' read -r label used t; do
    local same; same=$(awk -F'|' -v u="$used" '$1 ~ /^lancer,/ && $2 == u {print $3}' "$tmp/rows" | head -n 1)
    awk -v l="$label" -v u="$used" -v t="$t" -v b="$base" -v s="$same" 'BEGIN {
      o = (l ~ /^lancer-mpi/ && s != "") ? sprintf("%+.0f%%", 100 * (t / s - 1)) : "";
      printf "| %s | %d | %.2f | %.2f× | %s |\n", l, u, t, b / t, o }'
  done <"$tmp/rows"
}

echo "lancer-mpi on $(nproc) cores, median of $REPEAT runs ($(mpirun --version | head -n 1))"
bench still
bench animation
