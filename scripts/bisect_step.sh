#!/usr/bin/env bash
# One step of `git bisect run`: build this commit, then judge it with `iblcheck bisect`.
# Exit 0 good, 1 bad, 125 skip (the build fails, or iblcheck bisect cannot judge this commit: a
# shader that does not compile, a usage or input error, no driver).
#   cp -r goldens /tmp/goldens-good     # judge every commit against the same approved goldens
#   git bisect start BAD GOOD
#   git bisect run scripts/bisect_step.sh --goldens /tmp/goldens-good --filter 'mobile.roughness_sweep.*'
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
source "$root/scripts/cmake_env.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null 2>&1 || exit 125
cmake --build "$root/build" -j"$(nproc)" --target iblcheck >/dev/null 2>&1 || exit 125
exec "$root/build/iblcheck" bisect "$@"
