#!/usr/bin/env bash
# README command 2 (and .ci/run): set-up, build everything (scripts/build.sh --all), every test
# through CTest but the `slow` label's, then the sanitizer runs (scripts/sanitize.sh: ASan+UBSan unit tests, TSan over the
# runner; IBLCHECK_NO_SANITIZERS=1 skips them).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/build.sh" --all
# Left out unless IBLCHECK_SLOW_TESTS=1 (issue 33; tests/CMakeLists.txt): the `slow` label (the long
# sweeps; `cd build && ctest -L slow` runs it alone) and the ci suite's one-process-per-test form, the
# `ci-suite` label (`ctest -L ci-suite`), whose tests and verdicts `suite.ci` checks in one process.
exclude=(-LE '^(slow|ci-suite)$')
[[ "${IBLCHECK_SLOW_TESTS:-0}" == 1 ]] && exclude=()
(cd "$root/build" && ctest --output-on-failure -j"$(nproc)" "${exclude[@]}" "$@")
bash "$root/scripts/sanitize.sh"
