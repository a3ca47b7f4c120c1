#!/usr/bin/env bash
# README command 1: set-up, build, then the main job: the default (`ci`) suite on the built-in
# scenes, writing the report to report/ (report/index.html). Extra arguments go to `iblcheck run`.
# report/ is this script's own output: --force replaces the previous run's folder whole.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/build.sh"
cd "$root"
exec ./build/iblcheck run --suite ci --out report --force "$@"
