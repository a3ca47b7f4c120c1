#!/usr/bin/env bash
# Regenerates the CPU reference goldens under goldens/reference/ (<scene>__<env>.exr + .json).
# One command:  scripts/regenerate_reference_goldens.sh   (env: SPP=..., JOBS=..., BUILD_DIR=...)
# Each golden is rendered twice (seeds 0 and 1) to record its noise floor (relative RMSE between seeds,
# renderers/reference/reference.h); the seed-0 image is the golden.
# Expected time on a 2-core machine at the default SPP=2048: about 15 minutes in all
# (roughness_sweep 528x96: ~75 s per render, two renders per env; the others under a minute each).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-$ROOT/build}
JOBS=${JOBS:-2}
SPP=${SPP:-2048}
OUT=$ROOT/goldens/reference
if [[ ! -f "$BUILD_DIR/CMakeCache.txt" ]]; then
  cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
cmake --build "$BUILD_DIR" -j"$JOBS" --target iblcheck_reference_tool >/dev/null
TOOL=$(find "$BUILD_DIR" -name iblcheck_reference_tool -type f -perm -u+x | head -1)
mkdir -p "$OUT"
start=$(date +%s)
render() { # scene env [spp]: the file name is harness/golden_store.h's reference_key (':' '/' -> '-')
  local scene=$1 env=$2 spp=${3:-$SPP} name
  name="${scene}__${env//[:\/]/-}"
  "$TOOL" --scene "$scene" --env "$env" --spp "$spp" --seed 0 --noise-floor \
    --out "$OUT/$name.exr" --meta "$OUT/$name.json" \
    --command "scripts/regenerate_reference_goldens.sh (SPP=$SPP)"
}
render roughness_sweep studio
render roughness_sweep sky_sun
render roughness_sweep blender:sunrise
render roughness_sweep blender:interior
render furnace constant:1
render furnace_dielectric constant:1
render sphere studio
render grazing studio
echo "[goldens] done in $(( $(date +%s) - start )) s -> $OUT"
