#!/usr/bin/env bash
# README command 2 (and .ci/run): set-up, build everything (scripts/build.sh --all), every test
# through CTest but the `slow` label's, then the sanitizer runs (scripts/sanitize.sh: ASan+UBSan unit tests, TSan over the
# runner; IBLCHECK_NO_SANITIZERS=1 skips them).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/build.sh" --all
# The `slow` label (tests/CMakeLists.txt: the long sweeps) is left out unless IBLCHECK_SLOW_TESTS=1;
# `cd build && ctest -L slow` runs it alone (issue 33).
exclude=(-LE slow)
[[ "${IBLCHECK_SLOW_TESTS:-0}" == 1 ]] && exclude=()
(cd "$root/build" && ctest --output-on-failure -j"$(nproc)" "${exclude[@]}" "$@")
bash "$root/scripts/sanitize.sh"
