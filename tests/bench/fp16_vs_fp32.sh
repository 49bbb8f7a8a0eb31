#!/usr/bin/env bash
# Paper 000's fp16-against-fp32 comparison (Himmler & Günther 2026, §IV-D: "the FLIP metric
# shows that the differences are negligible"), rerun on every built-in scene: the scene optimised
# with each storage precision (same settings, same jitter seed), both optimised images and both
# unoptimised ones compared by `visopt image-diff` (PSNR, SSIM, LDR-FLIP mean and 95th percentile). Prints a
# Markdown table; the images and FLIP error maps stay in OUT_DIR.
#
# usage: tests/bench/fp16_vs_fp32.sh [BUILD_DIR [OUT_DIR]]   defaults: build, a temporary folder
# environment: RESOLUTION (default 128, the scenes' own), SIZE (default 512x512, the CLI's),
#   SCENES (default: all built-ins)
# At the defaults the whole run takes about 3-5 minutes on 2 cores.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
out="${2:-$(mktemp -d)}"
visopt="$build/bin/visopt"
[[ -x "$visopt" ]] || { echo "fp16_vs_fp32.sh: $visopt not found; build first" >&2; exit 1; }
mkdir -p "$out"
resolution="${RESOLUTION:-128}"
size="${SIZE:-512x512}"
scenes="${SCENES:-$("$visopt" scenes --json | python3 -c 'import json,sys; print(" ".join(s["name"] for s in json.load(sys.stdin)["scenes"]))')}"

row() {  # scene, what, reference png, test png, error map
  "$visopt" image-diff "$3" "$4" --json --error-map "$5" | python3 -c '
import json, sys
j = json.load(sys.stdin)
psnr = "identical" if j["identical"] else "%.1f" % j["psnr_db"]
ssim = "n/a" if j["ssim"] is None else "%.5f" % j["ssim"]
print("| %s | %s | %s | %s | %.5f | %.5f | %.4f |" % (sys.argv[1], sys.argv[2], psnr, ssim,
      j["flip"]["mean"], j["flip"]["p95"], j["flip"]["max"]))' "$1" "$2"
}

echo "fp16 against fp32, ${resolution}^3 scenes, ${size} images, $(date -u +%Y-%m-%d), $(nproc) cores"
echo
echo "| scene | image | PSNR (dB) | SSIM | FLIP mean | FLIP p95 | FLIP max |"
echo "|---|---|---|---|---|---|---|"
for scene in $scenes; do
  name="${scene#builtin:}"
  for p in fp32 fp16; do
    "$visopt" optimize --scene "$scene" --resolution "$resolution" --size "$size" \
      --precision "$p" --out "$out/$name-$p.png" --json >"$out/$name-$p.json" 2>"$out/$name-$p.log"
  done
  row "$name" unoptimised "$out/$name-fp32-before.png" "$out/$name-fp16-before.png" \
    "$out/$name-before-flip.png"
  row "$name" optimised "$out/$name-fp32.png" "$out/$name-fp16.png" "$out/$name-flip.png"
done
echo
echo "Images and error maps: $out"
