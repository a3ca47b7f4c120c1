#!/usr/bin/env bash
# Regenerates the reference goldens under goldens/reference/ (<scene>__<env>.exr + .json).
# One command:  scripts/regenerate_reference_goldens.sh   (env: BUILD_DIR=..., TEMPORAL=1 adds the temporal truth,
# TEMPORAL=only writes the temporal truth alone; LIST=1 prints the goldens' names and renders nothing;
# IBLCHECK=path uses that binary as it is instead of building BUILD_DIR's)
# Each golden's name is the binary's (`iblcheck truth --print-name`: harness/golden_store.h's
# reference_key), the name a suite test reads; the script keeps no naming rule of its own.
#
# The truth is the deterministic quadrature (renderers/reference/quadrature/truth_renderer.h; method and measurements in
# renderers/reference/CONVERGENCE.md): each golden is the finer of two refinement levels, and its sidecar states
# the error bound — the two levels' difference as relative RMSE and mean FLIP, per sphere and at the worst
# pixel — and whether issue 5's criterion (mean FLIP < 0.002, relative RMSE < 0.5 %) is met
# (error_bound.criterion). Deterministic: the same pixels on every run and thread count.
# The near-mirror sphere (roughness 0.02, the stability suite's) stays Monte Carlo (the quadrature refuses
# lobes with α < 2e-3 on smooth spheres): 8192 spp, its noise floor between lighting seeds in the sidecar.
# TEMPORAL=1 also writes the temporal suite's truth (bumpy_sphere, 32 frames under sky_sun and studio;
# sphere_field, 16 frames under sky_sun).
#
# Expected time (EXPECTED_TIME below, measured on this project's 2-core machine, see CONVERGENCE.md).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
source "$ROOT/scripts/cmake_env.sh"
BUILD_DIR=${BUILD_DIR:-$ROOT/build}
TEMPORAL=${TEMPORAL:-0}
LIST=${LIST:-0}
OUT=$ROOT/goldens/reference
EXPECTED_TIME="~6 min: 358 s wall, 634 s CPU (user), 2 threads, measured 2026-11-26 with only niced jobs beside it"
if [[ -n "${IBLCHECK:-}" ]]; then
  TOOL=$IBLCHECK
else
  if [[ ! -f "$BUILD_DIR/CMakeCache.txt" ]]; then
    cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  cmake --build "$BUILD_DIR" -j2 --target iblcheck >/dev/null
  TOOL="$BUILD_DIR/iblcheck"
fi
# The committed goldens, kept aside to state how far each new one is from it (mean FLIP, relative RMSE).
OLD=$(mktemp -d)
trap 'rm -rf "$OLD"' EXIT
if [[ "$LIST" != 1 ]]; then
  mkdir -p "$OUT"
  cp "$OUT"/*.exr "$OLD"/ 2>/dev/null || true
  echo "[goldens] expected: $EXPECTED_TIME"
fi
compare_old() { [[ -f "$OLD/$1.exr" ]] && echo --compare && echo "$OLD/$1.exr"; return 0; }
start=$(date +%s)
sets_of() { for kv in $(printf '%s\n' "$@" | sort); do printf -- '--set\n%s\n' "$kv"; done; }
name_of() { # scene env [truth options...]: the golden store's name, asked of the binary
  local scene=$1 env=$2
  shift 2
  "$TOOL" truth --print-name --scene "$scene" --env "$env" "$@"
}
still() { # "note" scene env [truth options...] -- [key=value...]: one still golden, named by the binary
  local note=$1 scene=$2 env=$3 name t0 opts=()
  shift 3
  while [[ $1 != -- ]]; do opts+=("$1"); shift; done
  shift
  mapfile -t sets < <(sets_of "$@")
  name=$(name_of "$scene" "$env" "${sets[@]}")
  if [[ "$LIST" == 1 ]]; then echo "$name"; return 0; fi
  t0=$(date +%s)
  mapfile -t cmp < <(compare_old "$name")
  "$TOOL" truth "${opts[@]}" --scene "$scene" --env "$env" "${sets[@]}" --out "$OUT/$name.exr" --force "${cmp[@]}" \
    --command "scripts/regenerate_reference_goldens.sh$note" || [[ $? == 1 ]] # 1: written, criterion not met
  echo "[goldens] $name: $(( $(date +%s) - t0 )) s"
}
truth() { # scene env [key=value...]: the quadrature truth
  still "" "$1" "$2" -- "${@:3}"
}
monte_carlo() { # scene env spp [key=value...]: the Monte Carlo integrator (seeds 0 and 1 for the noise floor)
  still " (spp=$3)" "$1" "$2" --integrator monte_carlo --spp "$3" --seed 0 -- "${@:4}"
}
sequence() { # scene env frames: the temporal truth, its frames stacked in one golden
  local scene=$1 env=$2 frames=$3 name t0
  name=$(name_of "$scene" "$env" --frames "$frames")
  if [[ "$LIST" == 1 ]]; then echo "$name"; return 0; fi
  t0=$(date +%s)
  "$TOOL" truth --frames "$frames" --scene "$scene" --env "$env" --out "$OUT/$name.exr" --force \
    --command "TEMPORAL=only scripts/regenerate_reference_goldens.sh" || [[ $? == 1 ]] # 1: criterion not met
  echo "[goldens] $name: $(( $(date +%s) - t0 )) s"
}
if [[ "$TEMPORAL" != only ]]; then
truth furnace constant:1
truth furnace_dielectric constant:1
truth sphere studio
truth grazing studio
monte_carlo sphere studio 8192 metallic=1 roughness=0.02
truth roughness_sweep studio
truth roughness_sweep sky_sun
truth roughness_sweep blender:sunrise
truth roughness_sweep blender:interior
fi
if [[ "$TEMPORAL" == 1 || "$TEMPORAL" == only ]]; then
sequence bumpy_sphere sky_sun 32
sequence bumpy_sphere studio 32
sequence sphere_field sky_sun 16
fi
[[ "$LIST" == 1 ]] && exit 0
# Wall time, and the CPU time of every render (user + sys of the finished children: the machine may be shared).
echo "[goldens] done in $(( $(date +%s) - start )) s wall -> $OUT"
# (`times` itself runs in this shell: in a pipeline it would report the pipeline's subshell, i.e. zero.)
times >"$OLD/times.txt"
tail -1 "$OLD/times.txt" | awk '{ print "[goldens] CPU of the renders (user, sys): " $1 ", " $2 }'
