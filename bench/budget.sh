#!/usr/bin/env bash
# The error budget on the gallery (make bench-budget): for each scene of scenes/gallery/ at
# W×H (default 640×480; the 32 reference renders take about 3 minutes on 2 cores), a
# render at the reference preset and one with --max-error E (default 0.02, mean FLIP),
# both on DOMAINS domains (default 2). Prints a Markdown table: the settings chosen, the
# predicted and the measured mean FLIP (lancer diff against the reference render), the
# search's rays against the chosen render's, its wall time against the rest of the
# process (what the settings chosen cost on their own: reading the scene, the render,
# writing the image), the search's, the chosen render's and the reference's times. The
# last columns say whether the image is within E, whether the search cost at most a fifth
# of what the settings chosen cost without it, both in rays (against the render's, which
# do not depend on the machine's load) and in time (against the rest of the process), and
# whether the render took less time than the reference. The --max-error render runs
# REPEAT times (default 3), its times are medians. Knobs: W, H, E, DOMAINS, REPEAT, SCENES
# (names without .rts).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}
W=${W:-640}; H=${H:-480}; E=${E:-0.02}; DOMAINS=${DOMAINS:-2}; REPEAT=${REPEAT:-3}
[ "$REPEAT" -ge 1 ] || { echo "bench-budget: REPEAT must be at least 1" >&2; exit 1; }
SCENES=${SCENES:-$(cd scenes/gallery && ls *.rts | sed 's/\.rts$//')}
tmp="$root/out/bench-budget"; mkdir -p "$tmp"

echo "scenes/gallery at ${W}×${H}, --max-error $E (mean FLIP), $DOMAINS domain(s), times of the --max-error render: medians of $REPEAT"
echo
echo "| scene | chosen settings | predicted FLIP | measured FLIP | search rays / render rays | search s / rest of the process s | search s | render s | reference s | within E | search ≤ 1/5 | faster |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|:-:|:-:|:-:|"
for s in $SCENES; do
  scene=scenes/gallery/$s.rts
  "$lancer" render "$scene" -W "$W" -H "$H" -j "$DOMAINS" -q --quality reference \
    -o "$tmp/$s.ref.png" --stats "$tmp/$s.ref.json"
  : >"$tmp/$s.times"
  for k in $(seq "$REPEAT"); do
    t0=$(date +%s.%N)
    "$lancer" render "$scene" -W "$W" -H "$H" -j "$DOMAINS" -q --max-error "$E" \
      -o "$tmp/$s.png" --stats "$tmp/$s.$k.json"
    t1=$(date +%s.%N)
    echo "$t0 $t1" >>"$tmp/$s.times"
  done
  "$lancer" diff "$tmp/$s.ref.png" "$tmp/$s.png" --json > "$tmp/$s.diff.json" || true
  python3 - "$s" "$E" "$REPEAT" "$tmp/$s" "$tmp/$s.ref.json" "$tmp/$s.diff.json" <<'PY'
import json, statistics, sys
name, e, repeat, base = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
ref, diff = map(lambda p: json.load(open(p)), sys.argv[5:])
runs = [json.load(open(f"{base}.{k}.json")) for k in range(1, repeat + 1)]
walls = [float(b) - float(a) for a, b in (l.split() for l in open(f"{base}.times"))]
# The run of the median wall time stands for the others (the choice is the same in each).
run = sorted(zip(walls, runs), key=lambda x: x[0])[(repeat - 1) // 2][1]
wall = statistics.median(walls)
search = statistics.median(r["max_error"]["search_seconds"] for r in runs)
render = statistics.median(r["render_seconds"] for r in runs)
b = run["max_error"]
rays = run["rays"]["total"]
settings = ", ".join(f"{k} {v}" for k, v in b["settings"].items())
ratio = b["search_rays"] / max(1, rays)
flip = diff["flip"]
# The whole process without its search is what the settings chosen cost on their own.
seconds = search / max(1e-9, wall - search)
print(f"| {name} | {settings} | {b['predicted_error']:.4f} | {flip:.4f} | {ratio:.3f} "
      f"| {seconds:.3f} | {search:.3f} | {render:.3f} | {ref['render_seconds']:.3f} "
      f"| {'yes' if flip <= e else 'no'} | {'yes' if ratio <= 0.2 and seconds <= 0.2 else 'no'} "
      f"| {'yes' if render < ref['render_seconds'] else 'no'} |")
PY
done
