#!/usr/bin/env bash
# AdEMAMix against Adam on the extinction optimisation (Himmler & Günther 2026, §III-A: "we
# observed a slightly improved convergence speed compared to the Adam method used in [9]"): each
# built-in scene with an importance optimised once with each optimiser, on one level with the
# same fixed budget (tolerance 0, so neither stops early) and everything else at the defaults.
# Prints a Markdown table: the energy E and the visibility V after 10, 30 and all iterations, and
# the iterations each needs for 90 % and 99 % of the larger of the two energy drops
# (E0 - min E_final). Energies of one scene compare across optimisers (same grid, same terms).
#
# usage: tests/bench/optimizer_comparison.sh [BUILD_DIR [OUT_DIR]]   defaults: build, a temp dir
# environment: RESOLUTION (default 64), SIZE (default 256x256), ITERATIONS (default 150),
#   SCENES (default: shepp-logan earth-mantle mixer hydrogen ct-head)
# At the defaults the whole run takes about 2-4 minutes on 2 cores.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
out="${2:-$(mktemp -d)}"
visopt="$build/bin/visopt"
[[ -x "$visopt" ]] || { echo "optimizer_comparison.sh: $visopt not found; build first" >&2; exit 1; }
mkdir -p "$out"
resolution="${RESOLUTION:-64}"
size="${SIZE:-256x256}"
iterations="${ITERATIONS:-150}"
scenes="${SCENES:-shepp-logan earth-mantle mixer hydrogen ct-head}"

for scene in $scenes; do
  for opt in ademamix adam; do
    "$visopt" optimize --scene "builtin:$scene" --resolution "$resolution" --size "$size" \
      --levels 1 --iterations "$iterations" --tolerance 0 --optimizer "$opt" --json \
      >"$out/$scene-$opt.json" 2>"$out/$scene-$opt.log"
  done
done

python3 - "$out" "$resolution" "$size" "$iterations" $scenes <<'EOF'
import json, sys, datetime, os
out, resolution, size, budget = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
scenes = sys.argv[5:]
print(f"AdEMAMix against Adam: {resolution}^3 scenes, {size} images, 1 level, {budget} iterations,"
      f" tolerance 0, {datetime.date.today()}, {os.cpu_count()} cores")
print()
print("| scene | optimiser | E(10) | E(30) | E(end) | V(10) | V(30) | V(end) | it. to 90 % | it. to 99 % | s |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for scene in scenes:
    runs = {}
    for opt in ("ademamix", "adam"):
        with open(f"{out}/{scene}-{opt}.json") as f:
            runs[opt] = json.load(f)
    e0 = runs["ademamix"]["iterations"][0]["energy"]
    best = min(min(it["energy"] for it in r["iterations"]) for r in runs.values())
    drop = e0 - best
    for opt, r in runs.items():
        its = r["iterations"]
        def at(k, key):
            return its[min(k, len(its)) - 1][key]
        def reach(frac):
            for i, it in enumerate(its):
                if drop > 0 and e0 - it["energy"] >= frac * drop:
                    return str(i + 1)
            return "-"
        print(f"| {scene} | {opt} | {at(10, 'energy'):.4e} | {at(30, 'energy'):.4e} | "
              f"{its[-1]['energy']:.4e} | {at(10, 'visibility_view'):.3f} | "
              f"{at(30, 'visibility_view'):.3f} | {its[-1]['visibility_view']:.3f} | "
              f"{reach(0.9)} | {reach(0.99)} | {r['times_ms']['optimize'] / 1000:.1f} |")
EOF
