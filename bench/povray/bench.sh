#!/usr/bin/env bash
# lancer against POV-Ray 3.7 on the equivalent scene pairs of scenes/bench/ (make bench-povray).
#
# For each pair, at W×H (default 1920×1080), without and with anti-aliasing (lancer
# --samples 3; POV-Ray +A0.0 +AM1 +R3: 3×3 samples in every pixel), with 1 and 2 workers
# (lancer --domains N; POV-Ray +WTN): the two programs alternate, REPEAT runs each (default
# 3), and the median wall time and peak memory (RSS) are reported with the ratio
# lancer/POV-Ray (below 1: lancer is faster), and whether it meets the target of at most
# half POV-Ray's time. Knobs: W, H, REPEAT, SCENES, WORKERS, AA.
#
# Then what one CSG object costs under an area light: csg_tube (a still life under a 4×4
# area light whose tube is the difference of two cylinders) against csg_tube_plain (the
# same without the tube), at TUBE_W×TUBE_H (default 960×720) on one worker, the four
# renders alternated TUBE_REPEAT times (default 7); the tube's cost is the difference of
# the two median wall times, and the target is lancer's at most POV-Ray's. Knobs: TUBE_W,
# TUBE_H, TUBE_REPEAT; TUBE=0 skips it.
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

[ "${TUBE:-1}" = 0 ] && exit 0
TW=${TUBE_W:-960}; TH=${TUBE_H:-720}; TR=${TUBE_REPEAT:-7}
# Wall seconds and processor seconds (user + system) of a command, to the millisecond.
wall() { local TIMEFORMAT='%R %U %S'; { time "$@" >/dev/null 2>"$tmp/err"; } 2>&1 || { cat "$tmp/err" >&2; return 1; }; }
for f in lt lp pt pp; do : >"$tmp/$f"; done
for _ in $(seq "$TR"); do
  wall "$lancer" render scenes/bench/csg_tube.rts -o "$tmp/l.png" --width "$TW" --height "$TH" --domains 1 -q >>"$tmp/lt"
  HOME="$tmp/home" wall povray +Iscenes/bench/csg_tube.pov "+O$tmp/p.png" "+W$TW" "+H$TH" -D -V -GA +WT1 -A \
    Display_Gamma=sRGB File_Gamma=sRGB >>"$tmp/pt"
  wall "$lancer" render scenes/bench/csg_tube_plain.rts -o "$tmp/l.png" --width "$TW" --height "$TH" --domains 1 -q >>"$tmp/lp"
  HOME="$tmp/home" wall povray +Iscenes/bench/csg_tube_plain.pov "+O$tmp/p.png" "+W$TW" "+H$TH" -D -V -GA +WT1 -A \
    Display_Gamma=sRGB File_Gamma=sRGB >>"$tmp/pp"
done
echo
echo "A CSG object under an area light (scenes/bench/csg_tube against csg_tube_plain, ${TW}×${TH}, one worker, median of $TR alternated runs):"
echo
# The medians of wall time, and of processor time: POV-Ray's wall time holds some 0.6 s
# of waiting between its threads (its processor time is about 1.0 of its 1.6 s at
# 960×720), and that waiting moves by tens of milliseconds from run to run.
cpu() { awk '{print $2 + $3}' "$1" | median; }
printf '| program | time | with the tube s | without s | the tube s |\n|---|---|---:|---:|---:|\n'
lt=$(awk '{print $1}' "$tmp/lt" | median); lp=$(awk '{print $1}' "$tmp/lp" | median)
pt=$(awk '{print $1}' "$tmp/pt" | median); pp=$(awk '{print $1}' "$tmp/pp" | median)
clt=$(cpu "$tmp/lt"); clp=$(cpu "$tmp/lp"); cpt=$(cpu "$tmp/pt"); cpp=$(cpu "$tmp/pp")
awk -v lt="$lt" -v lp="$lp" -v pt="$pt" -v pp="$pp" -v clt="$clt" -v clp="$clp" -v cpt="$cpt" -v cpp="$cpp" 'BEGIN {
  printf "| lancer | wall | %.3f | %.3f | %.3f |\n| POV-Ray | wall | %.3f | %.3f | %.3f |\n", lt, lp, lt - lp, pt, pp, pt - pp
  printf "| lancer | processor | %.3f | %.3f | %.3f |\n| POV-Ray | processor | %.3f | %.3f | %.3f |\n", clt, clp, clt - clp, cpt, cpp, cpt - cpp
  split("wall processor", name, " ")
  l[1] = lt - lp; p[1] = pt - pp; l[2] = clt - clp; p[2] = cpt - cpp
  for (i = 1; i <= 2; i++) {
    if (p[i] <= 0) { printf "\nin %s time, the tube costs POV-Ray too little to measure at this size", name[i]; continue }
    r = l[i] / p[i]
    printf "\nin %s time, the tube costs lancer %.2f× what it costs POV-Ray: target ≤ 1×, %s", name[i], r, (sprintf("%.2f", r) + 0 <= 1 ? "met" : "not met")
  }
  print ""
}'
