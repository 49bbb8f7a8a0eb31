#!/usr/bin/env bash
# Runs the render-throughput benchmark (bench_render) under a virtual X server and prints a
# Markdown table: visopt against VTK's vtkFixedPointVolumeRayCastMapper, Msamples/s per core.
# Builds nothing: build the bench_render target first (see docs/benchmarks.md).
#
# usage: tests/bench/run_render_bench.sh [BUILD_DIR_OR_BINARY]
#   default: build-bench/tests/bench/bench_render, then build/tests/bench/bench_render
# environment:
#   BENCH_FILTER    --benchmark_filter regex (default: all cases)
#   BENCH_MIN_TIME  --benchmark_min_time in seconds per repetition (default 0.5)
#   BENCH_REPS      --benchmark_repetitions (default 3); the table shows medians
#   BENCH_JSON      where to keep the raw Google Benchmark JSON (default: a temporary file)
#   VISOPT_BENCH_SCENE, VISOPT_BENCH_DUMP: passed through to bench_render
# With defaults the whole run takes about 4-6 minutes on 2 cores.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
arg="${1:-}"
bin=""
if [[ -n "$arg" && -f "$arg" && -x "$arg" ]]; then
  bin="$arg"
elif [[ -n "$arg" ]]; then
  bin="$arg/tests/bench/bench_render"
else
  for dir in "$root/build-bench" "$root/build"; do
    if [[ -x "$dir/tests/bench/bench_render" ]]; then
      bin="$dir/tests/bench/bench_render"
      break
    fi
  done
fi
if [[ -z "$bin" || ! -x "$bin" ]]; then
  echo "run_render_bench.sh: no bench_render binary found${bin:+ at $bin}; build it with" >&2
  echo "  cmake -S . -B build-bench -G Ninja -DVISOPT_BUILD_BENCHMARKS=ON &&" \
       "ninja -C build-bench bench_render" >&2
  exit 2
fi

json="${BENCH_JSON:-}"
cleanup=""
if [[ -z "$json" ]]; then
  json="$(mktemp --suffix=.json)"
  cleanup="$json"
fi
trap '[[ -n "$cleanup" ]] && rm -f "$cleanup"' EXIT

args=(--benchmark_min_time="${BENCH_MIN_TIME:-0.5}"
      --benchmark_repetitions="${BENCH_REPS:-3}"
      --benchmark_out="$json" --benchmark_out_format=json)
[[ -n "${BENCH_FILTER:-}" ]] && args+=(--benchmark_filter="$BENCH_FILTER")

# VTK's offscreen window is still an X (GLX) window with Debian's VTK: give it a virtual display.
runner=()
if command -v xvfb-run > /dev/null; then
  runner=(xvfb-run -a -s "-screen 0 1280x1024x24")
elif [[ -z "${DISPLAY:-}" ]]; then
  echo "run_render_bench.sh: xvfb-run not found and no DISPLAY: the VTK cases will be skipped" >&2
fi

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)" >&2
start=$(date +%s)
"${runner[@]}" "$bin" "${args[@]}" >&2
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg); $(( $(date +%s) - start )) s" >&2

python3 - "$json" <<'PY'
import json
import re
import statistics
import sys

with open(sys.argv[1]) as f:
    report = json.load(f)

name_re = re.compile(r"^(visopt|vtk_fixed_point)/size:(\d+)/image:(\d+)/tf:(\w+)(?:/(fp32|fp16))?")
runs = {}   # (renderer, size, image, tf, precision) -> list of per-repetition benchmark entries
errors = {}
for b in report["benchmarks"]:
    if b.get("run_type") != "iteration":
        continue
    m = name_re.match(b["name"])
    if not m:
        continue
    renderer, size, image, tf, precision = m.groups()
    key = (renderer, int(size), int(image), tf, precision or "")
    if b.get("error_occurred"):
        errors[key] = b.get("error_message", "error")
        continue
    runs.setdefault(key, []).append(b)


def median(key, counter):
    values = [b[counter] for b in runs.get(key, []) if counter in b]
    return statistics.median(values) if values else None


def fmt(x, digits=1):
    return "n/a" if x is None else f"{x:.{digits}f}"


ctx = report.get("context", {})
print(f"scene {ctx.get('scene', '?')}; visopt {ctx.get('visopt_backend', '?')}; "
      f"VTK mapper threads {ctx.get('vtk_threads', '?')}; {ctx.get('num_cpus', '?')} CPUs; "
      f"load average at start {', '.join(f'{x:.2f}' for x in ctx.get('load_avg', []))}")
print()
print("| volume | image | TF | precision "
      "| visopt Msamples/s/core | VTK Msamples/s/core | ratio "
      "| visopt Msamples/CPU-s | VTK Msamples/CPU-s | ratio (CPU) "
      "| visopt taken Msamples/CPU-s | visopt ms/frame | VTK ms/frame | CPU share visopt / VTK "
      "| T_L ms |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
keys = sorted({k for k in runs if k[0] == "visopt"} | {k for k in errors if k[0] == "visopt"},
              key=lambda k: (k[1], k[2], k[3] != "scene", k[4] != "fp32"))
for key in keys:
    _, size, image, tf, precision = key
    vtk = ("vtk_fixed_point", size, image, tf, "")
    cells = [f"{size}³", f"{image}²", tf, precision]
    for counter in ("Msps_core", "Msps_core_cpu"):
        ours, theirs = median(key, counter), median(vtk, counter)
        cells += [fmt(ours), "skipped" if vtk in errors else fmt(theirs),
                  fmt(ours / theirs if ours and theirs else None, 2)]
    cells += [fmt(median(key, "Msps_core_taken_cpu")), fmt(median(key, "ms_frame"), 0),
              fmt(median(vtk, "ms_frame"), 0),
              f"{fmt(median(key, 'cpu_util'), 2)} / {fmt(median(vtk, 'cpu_util'), 2)}",
              fmt(median(key, "light_ms"), 0)]
    print("| " + " | ".join(cells) + " |")
for key, message in sorted(errors.items()):
    print(f"\n{'/'.join(str(k) for k in key if k != '')}: {message}")
PY
