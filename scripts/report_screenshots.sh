#!/usr/bin/env bash
# Screenshots of the HTML report for reports/screenshots/ (issue 17), with each page's height:
#   ci_failure_first_screen.png  a ci run with one failure, the first 1440x900 screen
#   ci_failure_page.png          the same report, the whole page
#   nightly_first_screen.png     a nightly run, the first screen
#   nightly_charts.png           its Charts tab, the first 1440x1800
#   temporal_aa_verdict.png      a temporal run's Charts tab at its specular-AA verdict (issue 28)
#   temporal_aa_sweep.png        the same for a specular_aa_sweep.py run, when SWEEP_RUN=DIR names its output
# The failure is made the way a shader change makes one: a copy of the goldens in which the sky_sun
# Lagarde baseline was blessed from a shader whose Lagarde lerp factor lacks its square root, so
# today's shader differs from that baseline (and from no other).
#
#   scripts/report_screenshots.sh [OUT_DIR]     (default reports/screenshots)
#
# Takes the ci suite (~30 s) and the nightly suite (~1-3 min idle, ~12 min on a loaded 2-core
# machine), and the temporal suite (~1-2 min). NIGHTLY_RUN=DIR (TEMPORAL_RUN=DIR) reuses the results of an earlier `iblcheck run --suite nightly --out DIR`.
# Needs build/iblcheck and build/tests/report_browser (cmake --build build --target iblcheck report_browser).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
OUT=${1:-reports/screenshots}
export IBLCHECK_HDRI_DIR=${IBLCHECK_HDRI_DIR:-$PWD/.cache/blender-hdri}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$OUT"

cp -r renderers/shaders "$tmp/shaders"
cp -r goldens "$tmp/goldens"
sed -i 's/smoothness \* (sqrt(smoothness) + roughness)/smoothness * (smoothness + roughness)/' "$tmp/shaders/dominant_dir.glsl"
grep -q 'smoothness \* (smoothness + roughness)' "$tmp/shaders/dominant_dir.glsl" ||
  { echo "renderers/shaders/dominant_dir.glsl changed: update the edit in $0" >&2; exit 2; }
IBLCHECK_CACHE_DIR="$tmp/cache" IBLCHECK_SHADER_DIR="$tmp/shaders" \
  "$BUILD/iblcheck" bless --suite ci --goldens "$tmp/goldens" --filter 'mobile.roughness_sweep.sky_sun.dominant_dir=lagarde'
rc=0
"$BUILD/iblcheck" run --suite ci --goldens "$tmp/goldens" --out "$tmp/ci" -q || rc=$?
[[ $rc == 1 ]] || { echo "expected one failure (exit 1), got exit $rc" >&2; exit 2; }

if [[ -n "${NIGHTLY_RUN:-}" ]]; then
  "$BUILD/iblcheck" report "$NIGHTLY_RUN/results.json" --out "$tmp/nightly"
else
  "$BUILD/iblcheck" run --suite nightly --out "$tmp/nightly" -q
fi

if [[ -n "${TEMPORAL_RUN:-}" ]]; then
  "$BUILD/iblcheck" report "$TEMPORAL_RUN/results.json" --out "$tmp/temporal"
else
  "$BUILD/iblcheck" run --suite temporal --out "$tmp/temporal" -q
fi

shot="$BUILD/tests/report_browser"
"$shot" "$tmp/ci/index.html" --out "$OUT/ci_failure_first_screen.png"
"$shot" "$tmp/ci/index.html" --out "$OUT/ci_failure_page.png" --full
"$shot" "$tmp/nightly/index.html" --out "$OUT/nightly_first_screen.png"
"$shot" "$tmp/nightly/index.html" --out "$OUT/nightly_charts.png" --tab charts --height 1800
"$shot" "$tmp/temporal/index.html" --out "$OUT/temporal_aa_verdict.png" --tab charts --scroll-to aa-verdict --height 1300
if [[ -n "${SWEEP_RUN:-}" ]]; then
  "$BUILD/iblcheck" report "$SWEEP_RUN/results.json" --out "$tmp/sweep"
  "$shot" "$tmp/sweep/index.html" --out "$OUT/temporal_aa_sweep.png" --tab charts --scroll-to aa-verdict --height 1500
fi
