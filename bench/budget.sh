#!/usr/bin/env bash
# The error budget on the gallery (make bench-budget): for each scene of scenes/gallery/ at
# W×H (default 160×120, so that the reference renders are affordable on a small machine),
# a render at the reference preset and one with --max-error E (default 0.02, mean FLIP),
# both on DOMAINS domains (default 1). Prints a Markdown table: the settings chosen, the
# predicted and the measured mean FLIP (lancer diff against the reference render), the
# search's rays and time against the chosen render's, the chosen render's time and the
# reference's. The last columns say whether the image is within E, whether the search
# cost at most a fifth of the render (in rays, which do not depend on the machine's load),
# and whether the render took less time than the reference. Knobs: W, H, E, DOMAINS,
# SCENES (names without .rts).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
lancer=${LANCER:-"$root/_build/default/bin/main.exe"}
W=${W:-160}; H=${H:-120}; E=${E:-0.02}; DOMAINS=${DOMAINS:-1}
SCENES=${SCENES:-$(cd scenes/gallery && ls *.rts | sed 's/\.rts$//')}
tmp="$root/out/bench-budget"; mkdir -p "$tmp"

echo "scenes/gallery at ${W}×${H}, --max-error $E (mean FLIP), $DOMAINS domain(s)"
echo
echo "| scene | chosen settings | predicted FLIP | measured FLIP | search rays / render rays | search s | render s | reference s | within E | search ≤ 1/5 | faster |"
echo "|---|---|---:|---:|---:|---:|---:|---:|:-:|:-:|:-:|"
for s in $SCENES; do
  scene=scenes/gallery/$s.rts
  "$lancer" render "$scene" -W "$W" -H "$H" -j "$DOMAINS" -q --quality reference \
    -o "$tmp/$s.ref.png" --stats "$tmp/$s.ref.json"
  "$lancer" render "$scene" -W "$W" -H "$H" -j "$DOMAINS" -q --max-error "$E" \
    -o "$tmp/$s.png" --stats "$tmp/$s.json"
  "$lancer" diff "$tmp/$s.ref.png" "$tmp/$s.png" --json > "$tmp/$s.diff.json" || true
  python3 - "$s" "$E" "$tmp/$s.ref.json" "$tmp/$s.json" "$tmp/$s.diff.json" <<'PY'
import json, sys
name, e, ref, run, diff = sys.argv[1], float(sys.argv[2]), *map(lambda p: json.load(open(p)), sys.argv[3:])
b = run["max_error"]
rays = run["rays"]["total"]
settings = ", ".join(f"{k} {v}" for k, v in b["settings"].items())
ratio = b["search_rays"] / max(1, rays)
flip = diff["flip"]
print(f"| {name} | {settings} | {b['predicted_error']:.4f} | {flip:.4f} | {ratio:.3f} "
      f"| {b['search_seconds']:.3f} | {run['render_seconds']:.3f} | {ref['render_seconds']:.3f} "
      f"| {'yes' if flip <= e else 'no'} | {'yes' if ratio <= 0.2 else 'no'} "
      f"| {'yes' if run['render_seconds'] < ref['render_seconds'] else 'no'} |")
PY
done
