#!/usr/bin/env bash
# Sanitizer runs (issue 19), part of scripts/test.sh and so of CI:
#  - ASan + UBSan over the unit tests that need no GPU driver (metrics, verdicts, suites, scenes);
#  - TSan over the runner: a slice of the ci suite with two worker threads, judged against the
#    committed baselines, so every shared structure of `run` is exercised concurrently. FLIP's pixel
#    kernels are built without TSan's instrumentation (metrics/CMakeLists.txt: they touch only their
#    call's buffers, and instrumented they took the slice from 28.7 s to 51.5 s).
# Builds go to build-asan/ and build-tsan/ (separate from build/). Exit 1 on any finding.
# IBLCHECK_NO_SANITIZERS=1 skips this (e.g. for a quick local loop).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [[ "${IBLCHECK_NO_SANITIZERS:-0}" == 1 ]]; then echo "[sanitize] skipped (IBLCHECK_NO_SANITIZERS=1)"; exit 0; fi
jobs="$(nproc)"
source "$root/scripts/cmake_env.sh"
asan_tests=(test_units)

echo "[sanitize] ASan+UBSan build of ${asan_tests[*]}"
cmake -S "$root" -B "$root/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIBLCHECK_SANITIZE=address >/dev/null
build_or_fail() { # dir log targets...
  local dir="$1" log="$2"; shift 2
  if ! cmake --build "$dir" -j"$jobs" --target "$@" >"$log" 2>&1; then
    grep -E "error|Error" "$log" | head -20
    echo "[sanitize] build failed (log: $log)" >&2
    exit 1
  fi
}
build_or_fail "$root/build-asan" "$root/build-asan/build.log" "${asan_tests[@]}"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for t in "${asan_tests[@]}"; do
  if ! "$root/build-asan/tests/$t" --gtest_brief=1 >"$root/build-asan/$t.log" 2>&1; then
    tail -60 "$root/build-asan/$t.log"
    echo "[sanitize] FAIL: $t under ASan+UBSan (log: build-asan/$t.log)" >&2
    exit 1
  fi
  echo "[sanitize] ASan+UBSan clean: $t"
done

echo "[sanitize] TSan build of iblcheck"
cmake -S "$root" -B "$root/build-tsan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIBLCHECK_SANITIZE=thread >/dev/null
build_or_fail "$root/build-tsan" "$root/build-tsan/build.log" iblcheck
out="$(mktemp -d)" store="$(mktemp -d)" metrics_store="$(mktemp -d)"
log="$root/build-tsan/run.log"
# halt_on_error=0 so every race is listed; exitcode 66 marks a run that reported any.
export TSAN_OPTIONS="suppressions=$root/tests/sanitizers/tsan.supp:halt_on_error=0:exitcode=66:second_deadlock_stack=1"
set +e
# Empty precompute and metrics stores of its own: the workers compute and store every precompute
# and measure every comparison under TSan, as before the stores existed.
IBLCHECK_PRECOMPUTE_CACHE="$store" IBLCHECK_METRICS_CACHE="$metrics_store" IBLCHECK_CLI_PATH="$root/build-tsan/iblcheck" "$root/build-tsan/iblcheck" run --suite ci --jobs 2 -q \
  --filter 'mobile.roughness_sweep.studio.*' --out "$out" >"$log" 2>&1
rc=$?
set -e
rm -rf "$out" "$store" "$metrics_store"
if [[ $rc -ne 0 ]] || grep -q "WARNING: ThreadSanitizer" "$log"; then
  grep -A30 "WARNING: ThreadSanitizer" "$log" | head -120
  echo "[sanitize] FAIL: the runner under TSan (exit $rc; log: build-tsan/run.log)" >&2
  exit 1
fi
echo "[sanitize] TSan clean: $(grep -E '^[0-9]+ tests:' "$log" | head -1)"
