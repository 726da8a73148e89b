#!/usr/bin/env bash
# lancer against POV-Ray 3.7 on the equivalent scene pairs of scenes/bench/ (make bench-povray).
#
# For each pair, at W×H (default 1920×1080), without and with anti-aliasing (lancer
# --samples 3; POV-Ray +A0.0 +AM1 +R3: 3×3 samples in every pixel), with 1 and 2 workers
# (lancer --domains N; POV-Ray +WTN): the two programs alternate, REPEAT runs each (default
# 3), and the median wall time and peak memory (RSS) are reported with the ratio
# lancer/POV-Ray (below 1: lancer is faster), and whether it meets the target of at most
# half POV-Ray's time. Knobs: W, H, REPEAT, SCENES, WORKERS, AA.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"

command -v povray >/dev/null 2>&1 ||
  { echo "bench-povray: povray is not installed (make bench-povray installs it)" >&2; exit 1; }
dune build @install 2>&1 | tail -n 5
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}

W=${W:-1920}; H=${H:-1080}; REPEAT=${REPEAT:-3}
SCENES=${SCENES:-"three_spheres field_1000 field_10000 field_100000 mirrors_5 mirrors_10 mirrors_50 glass transforms"}
WORKERS=${WORKERS:-"1 2"}; AA=${AA:-"off on"}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/home"   # POV-Ray wants a writable user configuration directory

# Wall seconds and peak RSS (KiB) of a command, as "S KIB".
measure() { /usr/bin/time -f "%e %M" -o "$tmp/time" "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }; cat "$tmp/time"; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

printf '| scene | AA | workers | lancer s | POV-Ray s | lancer/POV-Ray | ≤ 0.5× | lancer MiB | POV-Ray MiB |\n'
printf '|---|---|---:|---:|---:|---:|---|---:|---:|\n'
for s in $SCENES; do
  for aa in $AA; do
    for n in $WORKERS; do
      if [ "$aa" = on ]; then la="--samples 3"; pa="+A0.0 +AM1 +R3"; else la="--samples 1"; pa="-A"; fi
      : >"$tmp/l"; : >"$tmp/p"
      for _ in $(seq "$REPEAT"); do
        measure "$lancer" render "scenes/bench/$s.rts" -o "$tmp/l.png" --width "$W" --height "$H" --domains "$n" $la -q >>"$tmp/l"
        HOME="$tmp/home" measure povray "+Iscenes/bench/$s.pov" "+O$tmp/p.png" "+W$W" "+H$H" -D -V -GA "+WT$n" $pa \
          Display_Gamma=sRGB File_Gamma=sRGB >>"$tmp/p"
      done
      lt=$(cut -d' ' -f1 "$tmp/l" | median); pt=$(cut -d' ' -f1 "$tmp/p" | median)
      lm=$(cut -d' ' -f2 "$tmp/l" | median); pm=$(cut -d' ' -f2 "$tmp/p" | median)
      awk -v s="$s" -v aa="$aa" -v n="$n" -v lt="$lt" -v pt="$pt" -v lm="$lm" -v pm="$pm" \
        'BEGIN { r = lt / pt; printf "| %s | %s | %d | %.2f | %.2f | %.2f | %s | %.0f | %.0f |\n", s, aa, n, lt, pt, r, (sprintf("%.2f", r) + 0 <= 0.5 ? "yes" : "no"), lm/1024, pm/1024 }'
    done
  done
done
