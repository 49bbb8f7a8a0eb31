#!/usr/bin/env bash
# A subset of the unit suite under AddressSanitizer + UndefinedBehaviorSanitizer (issue 13,
# item 7), built in the fuzz targets' folder, whose library is already instrumented: the tests of
# everything that reads a user's input (volumes, sessions, transfer functions, meshes, the CLI)
# and of the kernels at their numerical extremes (where a wrapped index once hid). .ci/test runs
# it after the fuzz targets; the whole suite under both sanitizers is in docs/robustness.md.
#
#   tests/sanitizers/run_unit_tests.sh        (VISOPT_FUZZ_BUILD_DIR: the build folder)
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${VISOPT_FUZZ_BUILD_DIR:-build-fuzz}
if [[ ! -f "$BUILD/CMakeCache.txt" ]]; then
  echo "run_unit_tests.sh: $BUILD is not configured; run tests/fuzz/run_fuzzers.sh first" >&2
  exit 2
fi
TESTS=(test_volume_io test_session test_transfer_function test_surface_source test_mesh_sdf
       test_image test_world_mask test_extinction_extremes test_context_extremes test_cli
       test_faults)
cmake -DVISOPT_BUILD_TESTS=ON "$BUILD" >"$BUILD.tests-configure.log" 2>&1 ||
  { cat "$BUILD.tests-configure.log"; exit 1; }
cmake --build "$BUILD" -j "${VISOPT_JOBS:-$(nproc)}" --target "${TESTS[@]}" visopt-cli
# Every report is fatal (-fno-sanitize-recover); leaks are reported at each process's exit.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
failed=()
for t in "${TESTS[@]}"; do
  start=$(date +%s)
  if "$BUILD/tests/$t" --gtest_brief=1 >"$BUILD/sanitized-$t.log" 2>&1; then
    echo "sanitized unit tests: $t ok ($(( $(date +%s) - start )) s)"
  else
    echo "sanitized unit tests: $t FAILED; its output:"
    tail -n 60 "$BUILD/sanitized-$t.log"
    failed+=("$t")
  fi
done
if (( ${#failed[@]} )); then
  echo "sanitized unit tests: failed: ${failed[*]}" >&2
  exit 1
fi
echo "sanitized unit tests: ${#TESTS[@]} executables passed under address,undefined"
