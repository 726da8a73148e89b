#!/usr/bin/env bash
# lancer against an Embree harness of its own (test/embree/lancer_embree.c) on the scenes of
# the speed table (make bench-limit): one domain against one Embree thread, whole processes,
# the same pixels (compared with lancer diff: edge pixels may differ, Embree being single
# precision). Prints the wall time and peak memory of each and their ratios, side by side.
# Knobs: W, H (the field's size, default 1920×1080), GRID (spheres per side of the loop,
# default 1000), NU, NV (the torus: 2·NU·NV triangles, default 1000×500).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"

if [ ! -f /usr/include/embree4/rtcore.h ]; then
  echo "bench-limit: skipped, libembree-dev (Embree 4) is not installed (make bench-limit installs it)"; exit 0
fi
command -v /usr/bin/time >/dev/null 2>&1 || { echo "bench-limit: GNU time is missing (make bench-limit installs it)" >&2; exit 1; }
dune build @install 2>&1 | tail -n 5
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}
W=${W:-1920}; H=${H:-1080}; GRID=${GRID:-1000}; NU=${NU:-1000}; NV=${NV:-500}
tmp=$(mktemp -d -p "$root/_build"); trap 'rm -rf "$tmp"' EXIT
cc -O2 -o "$tmp/lancer_embree" test/embree/lancer_embree.c -lembree4 -lm

measure() { /usr/bin/time -f "%e %M" -o "$tmp/time" "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }; cat "$tmp/time"; }

awk -v NU="$NU" -v NV="$NV" -f test/embree/torus.awk >"$tmp/torus.obj"
cat >"$tmp/torus.rts" <<RTS
settings { width: 64, height: 48 }
camera { position: (0, 3, -4), look_at: (0, 0, 0), fov: 50 }
light { position: (-3, 5, -4) }
mesh { file: "torus.obj" }
RTS
cat >"$tmp/grid.rts" <<RTS
let n = $GRID
settings { width: 64, height: 48 }
camera { position: (0, 0.6 * n, -0.9 * n), look_at: (0, 0, 0), fov: 50 }
light { position: (-0.4 * n, 0.8 * n, -0.6 * n) }
for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n / 2), radius: 0.4 } } }
RTS

printf '| work | lancer s | Embree s | lancer/Embree | lancer MiB | Embree MiB | memory ratio | same pixels |\n'
printf '|---|---:|---:|---:|---:|---:|---:|---|\n'
row() { # name, lancer scene, lancer size, embree arguments...
  local name=$1 scene=$2 w=$3 h=$4; shift 4
  read -r lt lm < <(measure "$lancer" render "$scene" -o "$tmp/l.png" --width "$w" --height "$h" --domains 1 -q)
  read -r et em < <(measure "$tmp/lancer_embree" "$@" "$w" "$h" "$tmp/e.ppm")
  local same
  same=$("$lancer" diff "$tmp/l.png" "$tmp/e.ppm" --tolerance 2 --max-share 0.01 2>&1 | head -n 1 || true)
  awk -v n="$name" -v lt="$lt" -v et="$et" -v lm="$lm" -v em="$em" -v s="$same" \
    'BEGIN { printf "| %s | %.2f | %.2f | %.1f× | %.0f | %.0f | %.1f× | %s |\n", n, lt, et, lt/et, lm/1024, em/1024, lm/em, s }'
}
row "scenes/bench/field_100000.rts, ${W}×${H}" scenes/bench/field_100000.rts "$W" "$H" field 316
row "$((2 * NU * NV)) triangles from an OBJ ($(du -m "$tmp/torus.obj" | cut -f1) MB), first pixel at 64×48" "$tmp/torus.rts" 64 48 mesh "$tmp/torus.obj"
row "$((GRID * GRID)) spheres from a loop, first pixel at 64×48" "$tmp/grid.rts" 64 48 grid "$GRID"
