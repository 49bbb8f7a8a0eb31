#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer) and runs
# each on its seed corpus, its saved corpus and its regression inputs (tests/regression/fuzz/
# TARGET). docs/robustness.md ("Fuzzing") has the figures of the last long run.
#
#   bash tests/fuzz/run_fuzzers.sh [--seconds S | --runs N] [--jobs J] [--only REGEX]
#
# --seconds S   each target runs S seconds (default 3: what .ci/test runs, ~1 min in all)
# --runs N      each target runs N executions instead (the long run: --runs 1000000)
# --jobs J      targets run J at a time (default: the number of cores)
# Exit 1 when any target found a crash, a leak, a hang (> 10 s on one input) or an input that
# needs more than 2 GiB; the input is kept under BUILD/fuzz-findings/TARGET. A one-line summary
# per target (executions, corpus size, outcome) goes to BUILD/fuzz-report.txt.
# Environment: VISOPT_FUZZ_BUILD_DIR (default build-fuzz), VISOPT_JOBS (build parallelism).
set -euo pipefail
cd "$(dirname "$0")/../.."
SECONDS_PER_TARGET=3
RUNS=""
JOBS=$(nproc)
ONLY="."
while (($#)); do
  case "$1" in
    --seconds) SECONDS_PER_TARGET=$2; shift 2 ;;
    --runs) RUNS=$2; shift 2 ;;
    --jobs) JOBS=$2; shift 2 ;;
    --only) ONLY=$2; shift 2 ;;
    *) echo "run_fuzzers.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
BUILD=${VISOPT_FUZZ_BUILD_DIR:-build-fuzz}
ROOT=$PWD

if ! command -v clang++ >/dev/null; then
  echo "run_fuzzers.sh: clang++ not found (apt-get install clang libclang-rt-14-dev)" >&2
  exit 2
fi
# -O1: the usual optimisation for fuzzing with sanitizers, and a shorter build than -O3; the
# native architecture as in the main build (without F16C, fp16 conversion falls back to
# _Float16, which clang 14 lacks on x86-64). An
# existing build folder is kept as it was configured.
[[ -f "$BUILD/CMakeCache.txt" ]] || CC=clang CXX=clang++ cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_C_FLAGS_RELEASE="-O1 -DNDEBUG" \
  -DVISOPT_CUDA=OFF -DVISOPT_BUILD_FUZZERS=ON \
  -DVISOPT_SANITIZE=address,undefined -DVISOPT_BUILD_TESTS=OFF -DVISOPT_BUILD_BENCHMARKS=OFF \
  -DVISOPT_BUILD_WORKSTATION=OFF >"$BUILD.configure.log" 2>&1 || { cat "$BUILD.configure.log"; exit 1; }
TARGETS=$(cd tests/fuzz && python3 -c '
import re
text = open("CMakeLists.txt").read()
names = []
for var, prefix in (("VISOPT_FUZZ_VOLUME_FORMATS", "fuzz_volume_"), ("VISOPT_FUZZ_MESH_FORMATS", "fuzz_mesh_")):
    body = re.search(r"set\(" + var + r"(.*?)\)", text, re.S).group(1)
    names += [prefix + e.split(":")[0] for e in body.split()]
names += re.findall(r"visopt_add_fuzzer\((fuzz_\w+) ", text)
print(" ".join(n for n in names if "$" not in n))')
TARGETS=$(tr ' ' '\n' <<<"$TARGETS" | grep -E -- "$ONLY" | tr '\n' ' ')
cmake --build "$BUILD" -j "${VISOPT_JOBS:-$(nproc)}" --target $TARGETS

python3 tests/fuzz/make_seeds.py "$BUILD/fuzz-seeds" >/dev/null
mkdir -p "$BUILD/fuzz-corpus" "$BUILD/fuzz-findings" "$BUILD/fuzz-logs"
# What visopt may plan to allocate (availableMemoryBytes): under the 2 GiB RSS limit below.
export VISOPT_MEMORY_LIMIT_MB=${VISOPT_MEMORY_LIMIT_MB:-1024}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

run_one() {
  local t=$1
  local corpus="$BUILD/fuzz-corpus/$t" seeds="$BUILD/fuzz-seeds/$t" regress="$ROOT/tests/regression/fuzz/$t"
  mkdir -p "$corpus" "$seeds" "$BUILD/fuzz-findings/$t"
  local budget=(-max_total_time="$SECONDS_PER_TARGET")
  [[ -n "$RUNS" ]] && budget=(-runs="$RUNS")
  local dirs=("$corpus" "$seeds")
  [[ -d "$regress" ]] && dirs+=("$regress")
  local log="$BUILD/fuzz-logs/$t.log" rc=0
  "$BUILD/fuzz/$t" "${budget[@]}" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$BUILD/fuzz-findings/$t/" "${dirs[@]}" >"$log" 2>&1 || rc=$?
  local runs
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  # What follows a reader (a render, an SDF conversion) on every input of the corpus: too slow
  # to run at each execution, run once on each distinct input the fuzzing kept.
  local replay="$BUILD/fuzz-logs/$t.downstream.log"
  if ((rc == 0)); then
    VISOPT_FUZZ_DOWNSTREAM=1 "$BUILD/fuzz/$t" -runs=0 -max_len=4096 -timeout=30 -rss_limit_mb=2048 \
      -artifact_prefix="$BUILD/fuzz-findings/$t/downstream-" "${dirs[@]}" >"$replay" 2>&1 || rc=$?
    log=$replay
  fi
  local outcome="ok"
  ((rc == 0)) || outcome="FINDING (exit $rc): $(grep -m1 -E 'ERROR:|runtime error|==ERROR' "$log" | cut -c1-160)"
  printf '%-28s %10s executions  corpus %5d (replayed downstream)  %s\n' "$t" "${runs:-?}" \
    "$(find "$corpus" -type f | wc -l)" "$outcome"
  return $rc
}
export -f run_one
export BUILD ROOT SECONDS_PER_TARGET RUNS

budget_text="$SECONDS_PER_TARGET s"
[[ -n "$RUNS" ]] && budget_text="$RUNS executions"
echo "visopt fuzz: $(wc -w <<<"$TARGETS") targets, $budget_text each, $JOBS at a time"
status=0
tr ' ' '\n' <<<"$TARGETS" | grep . | xargs -P "$JOBS" -I{} bash -c 'run_one {}' \
  | tee "$BUILD/fuzz-report.txt" || status=1
if ((status)); then
  echo "visopt fuzz: findings above; inputs in $BUILD/fuzz-findings, logs in $BUILD/fuzz-logs" >&2
  exit 1
fi
echo "visopt fuzz: no findings (report in $BUILD/fuzz-report.txt)"
