#!/usr/bin/env bash
# Issue 33's figures, measured in one run on this machine for this checkout and for a build of a
# base commit side by side (same moment, same load), with their ratios (this / base):
#   - the ci suite: this checkout with its precompute, cost and metrics stores empty (cold) and filled
#     (warm, a shader author's next run), the base (its SPIR-V cache warm after the first run); and
#     warm with --out (results, images and the report written);
#   - a bisect step (`iblcheck bisect` on the studio roughness sweep; the build excluded), and
#     whether an edit of one shader relinks the tool (it should not need to);
#   - with --nightly: the nightly suite (wall, CPU, peak memory); with --full-build: a fresh clone's
#     `scripts/build.sh --all` (ccache as it is).
# Each figure is printed with the machine's load (1-minute average) when it was taken: on a shared
# machine only the ratios of figures taken together mean much.
#   scripts/bench_speed.sh [--base REV] [--base-dir DIR] [--nightly] [--full-build] [--ci-run]
# The base is built (tool only) in a detached git worktree at DIR (default /tmp/base33, REV 6523c68).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
base_rev=6523c68 base_dir=/tmp/base33 nightly=0 full_build=0 ci_run=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --base) base_rev="$2"; shift 2 ;;
    --base-dir) base_dir="$2"; shift 2 ;;
    --nightly) nightly=1; shift ;;
    --full-build) full_build=1; shift ;;
    --ci-run) ci_run=1; shift ;;
    *) echo "bench_speed.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[[ -x "$root/build/iblcheck" ]] || { echo "bench_speed.sh: build/iblcheck missing: run scripts/build.sh" >&2; exit 2; }
if [[ ! -d "$base_dir" ]]; then git -C "$root" worktree add --detach "$base_dir" "$base_rev" >/dev/null; fi
[[ "$(git -C "$base_dir" rev-parse HEAD)" == "$(git -C "$root" rev-parse "$base_rev")" ]] ||
  { echo "bench_speed.sh: $base_dir is not at $base_rev" >&2; exit 2; }
if [[ ! -x "$base_dir/build/iblcheck" ]]; then
  echo "[bench] building the base ($base_rev) in $base_dir/build"
  cmake -S "$base_dir" -B "$base_dir/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  cmake --build "$base_dir/build" -j"$(nproc)" --target iblcheck >/dev/null
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
load() { cut -d' ' -f1 /proc/loadavg; }

# measure NAME DIR CMD...: runs CMD in DIR; prints wall, CPU (user+sys), peak memory and the load.
declare -A wall cpu
measure() {
  local name="$1" dir="$2"; shift 2
  local l; l="$(load)"
  (cd "$dir" && /usr/bin/time -f "%e %U %S %M" -o "$tmp/time" "$@" >"$tmp/$name.log" 2>&1) || true
  read -r w u s m <"$tmp/time"
  wall[$name]="$w"; cpu[$name]="$(echo "$u + $s" | bc)"
  printf '  %-28s %8.1f s wall %8.1f s CPU %7.0f MB peak   (load %s)\n' "$name" "$w" "${cpu[$name]}" "$(echo "$m / 1024" | bc)" "$l"
}
ratio() { printf '  %-28s %.2f wall, %.2f CPU\n' "$1/$2" "$(echo "${wall[$1]} / ${wall[$2]}" | bc -l)" "$(echo "${cpu[$1]} / ${cpu[$2]}" | bc -l)"; }

echo "[bench] $(nproc) cores; this: $(git -C "$root" rev-parse --short HEAD), base: $base_rev ($base_dir)"
echo "ci suite (iblcheck run --suite ci -q):"
store="$tmp/precompute"
# The counting twin's, the metrics' and the sequences' stores (issue 33) start empty with the precompute store:
# cold is cold.
export IBLCHECK_COST_CACHE="$tmp/cost" IBLCHECK_METRICS_CACHE="$tmp/metrics" IBLCHECK_SEQUENCE_CACHE="$tmp/sequences"
measure base_ci_first "$base_dir" build/iblcheck run --suite ci -q
IBLCHECK_PRECOMPUTE_CACHE="$store" measure this_ci_cold "$root" build/iblcheck run --suite ci -q
measure base_ci "$base_dir" build/iblcheck run --suite ci -q
IBLCHECK_PRECOMPUTE_CACHE="$store" measure this_ci_warm "$root" build/iblcheck run --suite ci -q
IBLCHECK_PRECOMPUTE_CACHE="$store" measure this_ci_warm_out "$root" build/iblcheck run --suite ci -q --out "$tmp/ci_out"
measure base_ci_out "$base_dir" build/iblcheck run --suite ci -q --out "$tmp/ci_out_base"
grep -h "tests:" "$tmp/this_ci_warm.log" "$tmp/base_ci.log" | sed 's/^/    /'
ratio this_ci_cold base_ci
ratio this_ci_warm base_ci
ratio this_ci_warm_out base_ci_out

echo "bisect step (iblcheck bisect --filter 'mobile.roughness_sweep.studio.*', build excluded):"
measure base_bisect "$base_dir" build/iblcheck bisect --filter 'mobile.roughness_sweep.studio.*'
IBLCHECK_PRECOMPUTE_CACHE="$store" measure this_bisect "$root" build/iblcheck bisect --filter 'mobile.roughness_sweep.studio.*'
ratio this_bisect base_bisect
echo "a shader edit, then the tool's build (a bisect step's build):"
for tree in "$base_dir" "$root"; do
  f="$tree/renderers/shaders/brdf.glsl"
  cp "$f" "$tmp/brdf.glsl.orig"
  echo "// bench_speed.sh: a shader-only edit" >>"$f"
  l="$(load)"
  s=$(date +%s.%N)
  out="$(cmake --build "$tree/build" -j"$(nproc)" --target iblcheck 2>&1)"
  e=$(date +%s.%N)
  cp "$tmp/brdf.glsl.orig" "$f"
  relinked=no; grep -q "Linking" <<<"$out" && relinked=yes
  printf '  %-28s %8.1f s, relinked: %s   (load %s)\n' "$(basename "$tree")" "$(echo "$e - $s" | bc)" "$relinked" "$l"
  cmake --build "$tree/build" -j"$(nproc)" --target iblcheck >/dev/null 2>&1
done

if [[ $nightly == 1 ]]; then
  echo "nightly suite (iblcheck run --suite nightly -q):"
  # Blender's HDRIs as scripts/setup.sh extracted them here (the base worktree never ran it: without
  # them 94 of its 223 tests were errors).
  export IBLCHECK_HDRI_DIR="$root/.cache/blender-hdri"
  measure base_nightly "$base_dir" build/iblcheck run --suite nightly -q
  IBLCHECK_PRECOMPUTE_CACHE="$store" measure this_nightly_cold "$root" build/iblcheck run --suite nightly -q
  IBLCHECK_PRECOMPUTE_CACHE="$store" measure this_nightly_warm "$root" build/iblcheck run --suite nightly -q
  ratio this_nightly_cold base_nightly
  ratio this_nightly_warm base_nightly
fi
if [[ $full_build == 1 ]]; then
  echo "full build from a fresh clone (scripts/build.sh --all):"
  git clone -q "$root" "$tmp/clone_this"
  git clone -q "$root" "$tmp/clone_base" && git -C "$tmp/clone_base" checkout -q "$base_rev"
  measure base_full_build "$tmp/clone_base" bash scripts/build.sh --all
  measure this_full_build "$tmp/clone_this" bash scripts/build.sh --all
  ratio this_full_build base_full_build
  rm -rf "$tmp/clone_this/build" "$tmp/clone_base/build"
  CCACHE_DISABLE=1 measure base_full_build_no_ccache "$tmp/clone_base" bash scripts/build.sh --all
  CCACHE_DISABLE=1 measure this_full_build_no_ccache "$tmp/clone_this" bash scripts/build.sh --all
  ratio this_full_build_no_ccache base_full_build_no_ccache
fi
if [[ $ci_run == 1 ]]; then
  echo ".ci/run from a fresh clone (ccache as it is; ../shared linked beside each clone):"
  for which in base this; do
    mkdir -p "$tmp/ci_$which"
    git clone -q "$root" "$tmp/ci_$which/main"
    [[ $which == base ]] && git -C "$tmp/ci_$which/main" checkout -q "$base_rev"
    [[ -d "$root/../shared" ]] && ln -s "$(cd "$root/../shared" && pwd)" "$tmp/ci_$which/shared"
    CI=true measure "${which}_ci_run" "$tmp/ci_$which/main" bash .ci/run
  done
  ratio this_ci_run base_ci_run
fi
