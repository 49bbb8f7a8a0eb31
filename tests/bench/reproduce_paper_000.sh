#!/usr/bin/env bash
# Reruns what docs/paper-000.md shows of paper 000 (Himmler & Günther 2026) on our data, from the
# built-in scenes and, where present, the Cranium CT of datasets-scripts/fetch_datasets.sh:
#   fig3-*          Fig. 3's three cases (builtin:level-set-cases), before and after
#   fig4-*          Fig. 4: the earth mantle's crust filled and as a thin shell
#   light-term-*    the light term (R1, Eq. 13): builtin:ct-head with r = 0 and the default r = q
#   fig6-*          Fig. 6's volume ambient occlusion on the Cranium CT, with and without
#   fig7-*          Fig. 7's deviation view and a second viewpoint (earth mantle)
#   fig8-*          Fig. 8's view-space masks (lenses of strength 0 on the default scene)
#   fig9-*          Fig. 9's world-space mask (stand-in continents on the earth mantle)
#   fig10-*         Fig. 10's four methods and ClearView (level-set cases; the Cranium CT)
#   fig11-*         Fig. 11's lambda study: the mixer and the earth mantle with thin shells
#   fp16-fp32.md    fp16 against fp32 by FLIP (tests/bench/fp16_vs_fp32.sh)
#   optimizers.md   AdEMAMix against Adam (tests/bench/optimizer_comparison.sh)
#   table1.md       Table I per level and precision beside the paper's (tests/bench/table1.sh)
# Each image is the `visopt` command beside it; a log per command is kept next to its image. The
# figures' rows (fig11-mixer.png, ...) are put together by tests/bench/png_row.py.
#
# usage: tests/bench/reproduce_paper_000.sh [BUILD_DIR [OUT_DIR]]   defaults: build, a temp dir
#   (OUT_DIR=docs/paper-000 refreshes the documentation's images in place)
# environment: DATA (default data), SKIP_SLOW=1 leaves out the Cranium Fig. 10 row (~14 min on
#   2 cores) and Table I (~8 min), SKIP_TABLES=1 leaves out the three tables.
# At the defaults the whole run takes about 30 minutes on 2 cores (SKIP_SLOW=1: about 4).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
out="${2:-$(mktemp -d)}"
visopt="$build/bin/visopt"
[[ -x "$visopt" ]] || { echo "reproduce_paper_000.sh: $visopt not found; build first" >&2; exit 1; }
mkdir -p "$out"
data="${DATA:-$root/data}"
cranium="$data/Cranium.raw"

step() {  # name, then the visopt arguments; the image is $out/name.png
  local name="$1"
  shift
  echo "== $name: visopt $*" >&2
  local t0=$SECONDS
  "$visopt" "$@" --out "$out/$name.png" >"$out/$name.log" 2>&1 ||
    { echo "reproduce_paper_000.sh: $name failed, see $out/$name.log" >&2; exit 1; }
  echo "   $((SECONDS - t0)) s" >&2
}

# Fig. 3: the three cases of a context surface.
step fig3-level-set-cases optimize --scene builtin:level-set-cases --size 480x260

# The light term, off and at its default.
step light-term-ct-head-r0 optimize --scene builtin:ct-head --size 256x256 --r 0
step light-term-ct-head-r40 optimize --scene builtin:ct-head --size 256x256

# Fig. 7: the deviation view, and the frozen result from a second viewpoint.
step fig7-earth-mantle-deviation optimize --scene builtin:earth-mantle --size 320x320 \
  --deviation-view --view-from 60,25,2.6

# Fig. 4: the earth mantle's crust as a filled surface (the scene's own) and as a thin shell.
step fig4-earth-mantle-filled optimize --scene builtin:earth-mantle --size 256x256 --filled
step fig4-earth-mantle-shell optimize --scene builtin:earth-mantle --size 256x256 --shell 3

# Fig. 8: view-space masks, as importance lenses of strength 0 (they hide the importance under
# them): three placements over the default scene, beside the same run without one.
step fig8-no-lens optimize --scene builtin:shepp-logan --size 320x320
step fig8-lens optimize --scene builtin:shepp-logan --size 320x320 --lens 120,160,50,0
step fig8-lens-top optimize --scene builtin:shepp-logan --size 320x320 --lens 175,95,45,0
step fig8-lens-right optimize --scene builtin:shepp-logan --size 320x320 --lens 205,175,40,0

# Fig. 9: a world-space mask keeping the crust over stand-in continents (our earth has none:
# tests/bench/continents_mask.py writes five fixed caps), beside the run without it.
python3 "$root/tests/bench/continents_mask.py" 128 "$out/fig9-continents-mask.raw"
step fig9-earth-mantle-no-mask optimize --scene builtin:earth-mantle --size 256x256
step fig9-earth-mantle-mask optimize --scene builtin:earth-mantle --size 256x256 \
  --world-mask "$out/fig9-continents-mask.raw"

# Fig. 10: the baselines as defined, ours, and ClearView.
step fig10-level-set-cases compare --scene builtin:level-set-cases --resolution 96 --size 256x256

# Fig. 11: lambda, thin shells (3 mm to either side of the surface, ~2 voxels at 128^3).
for scene in mixer earth-mantle; do
  for lambda in 0.1 0.3 0.6 0.9; do
    step "fig11-$scene-lambda-$lambda" optimize --scene "builtin:$scene" --size 256x256 \
      --shell 3 --lambda "$lambda"
  done
done

if [[ -f "$cranium" ]]; then
  # Fig. 6: volume ambient occlusion on a real CT.
  step fig6-volume-ao-cranium render --volume "$cranium" --tf preset:ct-bone \
    --camera 0,-80,2.2 --size 320x320
  step fig6-volume-ao-cranium-off render --volume "$cranium" --tf preset:ct-bone \
    --camera 0,-80,2.2 --size 320x320 --no-ambient-occlusion
  if [[ -z "${SKIP_SLOW:-}" ]]; then
    step fig10-cranium compare --volume "$cranium" --tf preset:ct-skin-bone --context iso:-400 \
      --camera 0,10,2.4 --size 256x256 --levels 2 --iterations 20
  fi
else
  echo "reproduce_paper_000.sh: $cranium not found (datasets-scripts/fetch_datasets.sh):" \
    "leaving out Fig. 6 and the Cranium row of Fig. 10" >&2
fi

# The rows docs/paper-000.md shows, panels left to right.
row() {  # out, then the panels (names without .png, in $out)
  local name="$1"
  shift
  python3 "$root/tests/bench/png_row.py" "$out/$name.png" "${@/#/$out/}" ||
    { echo "reproduce_paper_000.sh: could not assemble $name" >&2; exit 1; }
}
for scene in mixer earth-mantle; do
  panels=()
  for lambda in 0.1 0.3 0.6 0.9; do panels+=("fig11-$scene-lambda-$lambda.png"); done
  row "fig11-$scene" "${panels[@]}"
done
row fig7-earth-mantle fig7-earth-mantle-deviation-before.png fig7-earth-mantle-deviation.png \
  fig7-earth-mantle-deviation-view.png
row fig4-earth-mantle fig4-earth-mantle-filled.png fig4-earth-mantle-shell.png
row fig8-lens-row fig8-no-lens.png fig8-lens.png fig8-lens-top.png fig8-lens-right.png
row fig9-earth-mantle fig9-earth-mantle-no-mask.png fig9-earth-mantle-mask.png
row light-term-ct-head light-term-ct-head-r0.png light-term-ct-head-r40.png

if [[ -z "${SKIP_TABLES:-}" ]]; then
  "$root/tests/bench/fp16_vs_fp32.sh" "$build" "$out/fp16-fp32" >"$out/fp16-fp32.md"
  "$root/tests/bench/optimizer_comparison.sh" "$build" "$out/optimizers" >"$out/optimizers.md"
  if [[ -z "${SKIP_SLOW:-}" ]]; then
    DATA="$data" "$root/tests/bench/table1.sh" "$build" "$out/table1" >"$out/table1.md"
  fi
fi
echo "reproduce_paper_000.sh: done; images and tables in $out" >&2
