#!/usr/bin/env bash
# lancer's speed targets, side by side in one run (make bench-limit): each row is a piece of
# work, lancer's figure, the reference's, their ratio, the target and whether it is met.
#
#   * against Embree (an own harness, bench/embree/lancer_embree.c, one thread; lancer on one
#     domain): the 100 000-sphere field at W×H, a torus of 2·NU·NV triangles read from an OBJ
#     and shaded flat as the harness shades it (time and peak memory; then lancer's default,
#     normals computed, against flat), GRID² spheres made by a loop of the scene language (time,
#     and lancer's whole render and peak memory on their own) and the same spheres each
#     with a colour computed in the loop (time and peak memory, Embree storing a colour
#     per sphere). The pixels are compared with
#     lancer diff: edge pixels may differ, Embree being single precision;
#   * a CSG object of a closed mesh against the mesh alone: the difference of a torus of
#     2·CSG_NU·CSG_NV triangles (default 200×100: 40 000) and a box, against the torus by
#     itself, both read from the OBJ and rendered at 160×120 on one domain;
#   * an animation against one still of it: `lancer bench animation` of
#     scenes/bench/field_moving.rts (24 frames at 480×270, one domain);
#   * the scene language against CPython: a loop of 3 000 001 sin·cos in `lancer check`
#     against the same loop in python3;
#   * reading a generated scene: LITERAL sphere blocks written out, as exporters and
#     scripts write them (bench/embree/literal_spheres.awk), read, checked and evaluated by
#     `lancer check` (MB/s), beside POV-Ray on the same scene in its own language (a 1×1
#     render, and the parse time it reports) when povray is installed.
#
# Whole processes, the two sides alternated REPEAT times (default 3), medians. A row whose
# tool is missing (Embree, GNU time, python3) says so and is skipped. Knobs: W, H (default
# 1920×1080), GRID (default 1000), NU, NV (default 1000×500), CSG_NU, CSG_NV, REPEAT, LOOP
# (iterations - 1, default 3000000), ANIMATION_TARGET (default 4), LITERAL (default 100000).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"

command -v /usr/bin/time >/dev/null 2>&1 || { echo "bench-limit: GNU time is missing (make bench-limit installs it)" >&2; exit 1; }
dune build @install ./bench/lancer_bench.exe 2>&1 | tail -n 5
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}
lancer_bench=${LANCER_BENCH:-"$root/_build/default/bench/lancer_bench.exe"}
W=${W:-1920}; H=${H:-1080}; GRID=${GRID:-1000}; NU=${NU:-1000}; NV=${NV:-500}
CSG_NU=${CSG_NU:-200}; CSG_NV=${CSG_NV:-100}
REPEAT=${REPEAT:-3}; LOOP=${LOOP:-3000000}; ANIMATION_TARGET=${ANIMATION_TARGET:-4}
LITERAL=${LITERAL:-100000}
mkdir -p "$root/_build"
tmp=$(mktemp -d -p "$root/_build"); trap 'rm -rf "$tmp"' EXIT

embree=yes
if [ ! -f /usr/include/embree4/rtcore.h ]; then
  embree="libembree-dev (Embree 4) is not installed (make bench-limit installs it)"
elif ! cc -O2 -o "$tmp/lancer_embree" bench/embree/lancer_embree.c -lembree4 -lm 2>"$tmp/cc"; then
  embree="the Embree harness did not build: $(head -n 1 "$tmp/cc")"
fi
python=$(command -v python3 || true)

# Wall seconds and peak RSS (KiB) of a command, as "S KIB".
measure() { /usr/bin/time -f "%e %M" -o "$tmp/time" "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }; cat "$tmp/time"; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
# Column C (1: seconds, 2: KiB) of file F, its median.
med() { cut -d' ' -f"$2" "$1" | median; }
# A row: work, lancer, reference, ratio, target, met, note.
out() { printf '| %s | %s | %s | %s | %s | %s | %s |\n' "$@"; }
# "yes" or "no": VALUE below or at LIMIT (below LIMIT with STRICT=1).
met() { case "$1" in [0-9]*) awk -v v="${1%×}" -v l="$2" -v s="${3:-0}" 'BEGIN { print ((s ? v < l : v <= l) ? "yes" : "no") }' ;; *) echo "—" ;; esac; }
# A / B to two decimals; "n/a" where B was too short to measure.
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.2f×", a / b; else printf "n/a" }'; }
secs() { awk -v s="$1" 'BEGIN { printf "%.2f s", s }'; }
mib() { awk -v k="$1" 'BEGIN { printf "%.0f MiB", k / 1024 }'; }

# Alternates `lancer render SCENE` (W×H, one domain) and the harness (ARGS W H) REPEAT
# times; medians in $tmp/l and $tmp/e ("S KIB" lines), agreement of the pixels in $tmp/same.
# Both write a binary PPM: the same work from the same pixels (a PNG's compression, which
# the harness does not do, is a tenth of lancer's time at 1920×1080).
pair() {
  local scene=$1 w=$2 h=$3; shift 3
  : >"$tmp/l"; : >"$tmp/e"; echo "—" >"$tmp/same"
  for _ in $(seq "$REPEAT"); do
    measure "$lancer" render "$scene" -o "$tmp/l.ppm" --width "$w" --height "$h" --domains 1 -q >>"$tmp/l"
    if [ "$embree" = yes ]; then measure "$tmp/lancer_embree" "$@" "$w" "$h" "$tmp/e.ppm" >>"$tmp/e"; fi
  done
  if [ "$embree" = yes ]; then
    { "$lancer" diff "$tmp/l.ppm" "$tmp/e.ppm" --tolerance 2 --max-share 0.01 2>&1 || true; } |
      head -n 1 | sed -E -e 's/.*max difference 0\/255.*/identical pixels/' \
        -e 's/.*max difference ([0-9]+)\/255.*, ([0-9]+) pixels \(([0-9.]+%)\) over the threshold.*/max difference \1\/255, \2 pixels (\3) beyond 2\/255/' >"$tmp/same"
  fi
}
# A row of lancer against Embree: work, lancer's figure, Embree's, target ratio, note.
against() {
  local work=$1 l=$2 e=$3 target=$4 note=$5 show
  case "$work" in *memory*) show=mib ;; *) show=secs ;; esac
  if [ "$embree" = yes ]; then
    local r; r=$(ratio "$l" "$e")
    out "$work" "$($show "$l")" "Embree $($show "$e")" "$r" "≤ ${target}×" "$(met "$r" "$target")" "$note"
  else
    out "$work" "$($show "$l")" "Embree: skipped" "—" "≤ ${target}×" "—" "$embree"
  fi
}

awk -v NU="$NU" -v NV="$NV" -f bench/embree/torus.awk >"$tmp/torus.obj"
cat >"$tmp/torus.rts" <<RTS
settings { width: 64, height: 48 }
camera { position: (0, 3, -4), look_at: (0, 0, 0), fov: 50 }
light { position: (-3, 5, -4) }
mesh { file: "torus.obj", smooth: false }
RTS
# The same mesh as lancer shades it by default: vertex normals computed from the faces.
sed 's|, smooth: false }| }|' "$tmp/torus.rts" >"$tmp/torus_smooth.rts"
cat >"$tmp/grid.rts" <<RTS
let n = $GRID
settings { width: 64, height: 48 }
camera { position: (0, 0.6 * n, -0.9 * n), look_at: (0, 0, 0), fov: 50 }
light { position: (-0.4 * n, 0.8 * n, -0.6 * n) }
for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n / 2), radius: 0.4 } } }
RTS
sed 's|radius: 0.4 }|radius: 0.4, material: material { color: (i / n, j / n, 0.5) } }|' "$tmp/grid.rts" >"$tmp/gridc.rts"
printf 'for i in 0 to %d { let x = sin(i) * cos(i) }\n' "$LOOP" >"$tmp/loop.rts"
awk -v N="$LITERAL" -f bench/embree/literal_spheres.awk >"$tmp/literal.rts"
awk -v N="$LITERAL" -v POV=1 -f bench/embree/literal_spheres.awk >"$tmp/literal.pov"

echo "median of $REPEAT alternated runs, whole processes; lancer on one domain"
echo
printf '| work | lancer | reference | ratio | target | met | note |\n'
printf '|---|---:|---:|---:|---|---|---|\n'

pair scenes/bench/field_100000.rts "$W" "$H" field 316
against "scenes/bench/field_100000.rts, ${W}×${H}" "$(med "$tmp/l" 1)" "$(med "$tmp/e" 1)" 1.25 "$(cat "$tmp/same")"

# Flat-shaded, as the harness shades it (smooth: false): the same work, parse and build.
obj="$((2 * NU * NV)) triangles from an OBJ ($(du -m "$tmp/torus.obj" | cut -f1) MB), flat, first pixel at 64×48"
pair "$tmp/torus.rts" 64 48 mesh "$tmp/torus.obj"
ol=$(med "$tmp/l" 1)
against "$obj" "$ol" "$(med "$tmp/e" 1)" 1.25 "$(cat "$tmp/same")"
against "$obj: peak memory" "$(med "$tmp/l" 2)" "$(med "$tmp/e" 2)" 1.25 ""
# What lancer's default adds to it: the vertex normals it computes for a mesh that has none
# (no target; Embree's harness computes none). Alternated with the flat render.
: >"$tmp/s"; : >"$tmp/f"
for _ in $(seq "$REPEAT"); do
  measure "$lancer" render "$tmp/torus_smooth.rts" -o "$tmp/l.ppm" --domains 1 -q >>"$tmp/s"
  measure "$lancer" render "$tmp/torus.rts" -o "$tmp/l.ppm" --domains 1 -q >>"$tmp/f"
done
out "the same OBJ shaded smooth (lancer's default: vertex normals computed)" \
  "$(secs "$(med "$tmp/s" 1)"), $(mib "$(med "$tmp/s" 2)")" \
  "flat $(secs "$(med "$tmp/f" 1)"), $(mib "$(med "$tmp/f" 2)")" \
  "$(ratio "$(med "$tmp/s" 1)" "$(med "$tmp/f" 1)")" "—" "—" "what computing the normals costs"

grid="$((GRID * GRID)) spheres from a loop, first pixel at 64×48"
pair "$tmp/grid.rts" 64 48 grid "$GRID"
gl=$(med "$tmp/l" 1); gm=$(med "$tmp/l" 2)
against "$grid" "$gl" "$(med "$tmp/e" 1)" 5 "$(cat "$tmp/same")"
out "$grid: lancer's whole render" "$(secs "$gl")" "" "" "≤ 2 s" "$(met "$gl" 2)" ""
if [ "$embree" = yes ]; then
  out "$grid: peak memory" "$(mib "$gm")" "Embree $(mib "$(med "$tmp/e" 2)")" "$(ratio "$gm" "$(med "$tmp/e" 2)")" "< 300 MiB" "$(met "$gm" $((300 * 1024)) 1)" ""
else
  out "$grid: peak memory" "$(mib "$gm")" "" "" "< 300 MiB" "$(met "$gm" $((300 * 1024)) 1)" ""
fi
# The same spheres, each with a material { color: … } computed in the loop; Embree keeps
# a colour per sphere too.
gridc="$((GRID * GRID)) spheres from a loop, each its own colour, first pixel at 64×48"
pair "$tmp/gridc.rts" 64 48 gridc "$GRID"
gcm=$(med "$tmp/l" 2)
against "$gridc" "$(med "$tmp/l" 1)" "$(med "$tmp/e" 1)" 3 "$(cat "$tmp/same")"
if [ "$embree" = yes ]; then
  out "$gridc: peak memory" "$(mib "$gcm")" "Embree $(mib "$(med "$tmp/e" 2)")" "$(ratio "$gcm" "$(med "$tmp/e" 2)")" "< 300 MiB" "$(met "$gcm" $((300 * 1024)) 1)" ""
else
  out "$gridc: peak memory" "$(mib "$gcm")" "" "" "< 300 MiB" "$(met "$gcm" $((300 * 1024)) 1)" ""
fi
: >"$tmp/c"
for _ in $(seq "$REPEAT"); do measure "$lancer" check "$tmp/grid.rts" >>"$tmp/c"; done
grid_check="$(secs "$(med "$tmp/c" 1)"), $(mib "$(med "$tmp/c" 2)")"

# A closed mesh in a difference with a box, against the mesh alone (whole processes).
awk -v NU="$CSG_NU" -v NV="$CSG_NV" -f bench/embree/torus.awk >"$tmp/closed.obj"
for s in alone difference; do
  if [ "$s" = alone ]; then body='mesh { file: "closed.obj" }'
  else body='difference { mesh { file: "closed.obj" } box { min: (0, -1, -2), max: (2, 1, 2) } }'; fi
  cat >"$tmp/closed_$s.rts" <<RTS
settings { width: 160, height: 120 }
camera { position: (0, 3, -4), look_at: (0, 0, 0), fov: 50 }
light { position: (-3, 5, -4) }
$body
RTS
done
: >"$tmp/ca"; : >"$tmp/cd"
for _ in $(seq "$REPEAT"); do
  measure "$lancer" render "$tmp/closed_difference.rts" -o "$tmp/c.ppm" --domains 1 -q >>"$tmp/cd"
  measure "$lancer" render "$tmp/closed_alone.rts" -o "$tmp/c.ppm" --domains 1 -q >>"$tmp/ca"
done
cr=$(ratio "$(med "$tmp/cd" 1)" "$(med "$tmp/ca" 1)")
out "difference of a closed mesh of $((2 * CSG_NU * CSG_NV)) triangles and a box, 160×120" \
  "$(secs "$(med "$tmp/cd" 1)")" "the mesh alone $(secs "$(med "$tmp/ca" 1)")" "$cr" "≤ 2×" "$(met "$cr" 2)" \
  "from the OBJ, whole process"

# lancer bench animation alternates the two commands itself; its JSON: {"scene":..,
# "frames":N,"animation_s":A,"still_s":S,"ratio":R}.
anim=$("$lancer" bench animation scenes/bench/field_moving.rts --repeat "$REPEAT" --domains 1 --json)
field() { echo "$anim" | sed -n "s/.*\"$1\":\([-0-9.e+]*\).*/\1/p"; }
ar=$(ratio "$(field animation_s)" "$(field still_s)")
out "$(field frames) frames of scenes/bench/field_moving.rts at 480×270 (lancer animate)" \
  "$(secs "$(field animation_s)")" "one still $(secs "$(field still_s)")" "$ar" \
  "≤ ${ANIMATION_TARGET}×" "$(met "$ar" "$ANIMATION_TARGET")" "lancer bench animation"

loop="for i in 0 to $LOOP { let x = sin(i) * cos(i) } (lancer check)"
: >"$tmp/l"; : >"$tmp/p"
for _ in $(seq "$REPEAT"); do
  measure "$lancer" check "$tmp/loop.rts" >>"$tmp/l"
  if [ -n "$python" ]; then
    measure "$python" -c "import math
for i in range($((LOOP + 1))): x = math.sin(i) * math.cos(i)" >>"$tmp/p"
  fi
done
if [ -n "$python" ]; then
  pr=$(ratio "$(med "$tmp/l" 1)" "$(med "$tmp/p" 1)")
  out "$loop" "$(secs "$(med "$tmp/l" 1)")" "CPython $(secs "$(med "$tmp/p" 1)")" "$pr" "≤ 0.5×" "$(met "$pr" 0.5)" \
    "$("$python" -c 'import platform; print("Python", platform.python_version())')"
else
  out "$loop" "$(secs "$(med "$tmp/l" 1)")" "CPython: skipped" "—" "≤ 0.5×" "—" "python3 is not on the PATH (make bench-limit installs it)"
fi

# A generated scene read, checked and evaluated, in MB/s of its text; POV-Ray parses the
# same scene in its own language (a render of one pixel: its parse, its bounding and
# the process; the parse time it reports itself in the note).
literal="$LITERAL literal sphere blocks, $(awk -v b="$(wc -c <"$tmp/literal.rts")" 'BEGIN { printf "%.1f", b / 1e6 }') MB (lancer check)"
: >"$tmp/l"; : >"$tmp/p"; : >"$tmp/pp"
povray=$(command -v povray || true)
mkdir -p "$tmp/home"   # POV-Ray wants a writable user configuration directory
for _ in $(seq "$REPEAT"); do
  measure "$lancer" check "$tmp/literal.rts" >>"$tmp/l"
  if [ -n "$povray" ]; then
    HOME="$tmp/home" measure "$povray" "+I$tmp/literal.pov" "+O$tmp/p.png" +W1 +H1 -D -V +GS >>"$tmp/p"
    sed -n 's/.*Parse Time:.*(\([0-9.]*\) seconds).*/\1/p' "$tmp/err" >>"$tmp/pp"
  fi
done
lt=$(med "$tmp/l" 1)
rate=$(awk -v b="$(wc -c <"$tmp/literal.rts")" -v s="$lt" 'BEGIN { if (s > 0) printf "%.0f", b / 1e6 / s; else print 0 }')
fast=$(awk -v r="$rate" 'BEGIN { print (r >= 40 ? "yes" : "no") }')
if [ -n "$povray" ]; then
  pt=$(med "$tmp/p" 1)
  out "$literal" "$(secs "$lt"), $rate MB/s" "POV-Ray $(secs "$pt")" "$(ratio "$lt" "$pt")" "≥ 40 MB/s" "$fast" \
    "POV-Ray: a 1×1 render of the same scene, of which its parse $(secs "$(median <"$tmp/pp")")"
else
  out "$literal" "$(secs "$lt"), $rate MB/s" "POV-Ray: skipped" "—" "≥ 40 MB/s" "$fast" \
    "povray is not on the PATH (make bench-povray installs it)"
fi

# The evaluation of the spheres alone, in one process (lancer_bench language, its JSON).
lang=$("$lancer_bench" language --grid "$GRID" --repeat "$REPEAT" --json 2>/dev/null || true)
jget() { echo "$lang" | sed -n "s/.*\"$1\": *\([-0-9.e+]*\).*/\1/p" | head -n 1; }
echo
if [ -n "$(jget objects_seconds)" ]; then
  echo "The $((GRID * GRID)) spheres' evaluation alone (lancer_bench language --grid $GRID): $(secs "$(jget objects_seconds)"), $(jget minor_words_per_object | awk '{printf "%.0f", $1}') words allocated a sphere."
fi
echo "lancer check of the same scene (parse, evaluation, checks, estimates): $grid_check."
