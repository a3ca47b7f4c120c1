#!/usr/bin/env bash
# README command 2 (and .ci/run): set-up, build everything (scripts/build.sh --all), every test
# through CTest, then the sanitizer runs (scripts/sanitize.sh: ASan+UBSan unit tests, TSan over the
# runner; IBLCHECK_NO_SANITIZERS=1 skips them).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/build.sh" --all
(cd "$root/build" && ctest --output-on-failure -j"$(nproc)" "$@")
bash "$root/scripts/sanitize.sh"
