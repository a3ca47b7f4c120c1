#!/usr/bin/env bash
# Set-up (missing Debian packages) + configure + build into build/.
#   scripts/build.sh          the tool, build/iblcheck: all that run.sh and a bisect step need
#   scripts/build.sh --all    everything: the tool, the test programs, benchmarks (test.sh)
# The test programs are more than half of a fresh build's CPU time (issue 20), so run.sh does not
# wait for them.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
source "$root/scripts/cmake_env.sh"
target=(--target iblcheck)
case "${1:-}" in
  --all) target=() ;;
  "") ;;
  *) echo "build.sh: unknown argument '$1' (use --all or nothing)" >&2; exit 2 ;;
esac
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$root/build" -j"$(nproc)" "${target[@]}"
