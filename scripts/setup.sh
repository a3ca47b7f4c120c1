#!/usr/bin/env bash
# Installs everything iblcheck needs from Debian's packages (the report has no JavaScript library:
# its charts and image viewer are written by the program). Idempotent: installs only what is
# missing. Safe to run on every invocation of the README's commands; when nothing is missing it
# takes about a second.
set -euo pipefail

PACKAGES=(
  cmake g++ pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  glslang-dev glslang-tools spirv-tools
  libopenimageio-dev openimageio-tools
  libopencv-dev libopencv-contrib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev libfmt-dev
  clang-format clang-tidy
  libastcenc-dev
  xz-utils zlib1g-dev
)
# Optional, for build speed (the build works without them, cmake/build_speed.cmake): ccache caches
# compiles across rebuilds and bisect steps, lld links ~3x faster than gold/ld, Ninja builds several
# targets at once where Make builds them one by one (scripts/cmake_env.sh). Set
# IBLCHECK_NO_BUILD_TOOLS=1 to skip them.
if [[ "${IBLCHECK_NO_BUILD_TOOLS:-0}" != 1 ]]; then PACKAGES+=(ccache lld ninja-build); fi
# Optional: the report's browser test runs where chromium is present; set IBLCHECK_NO_CHROMIUM=1 to skip it.
if [[ "${IBLCHECK_NO_CHROMIUM:-0}" != 1 ]]; then PACKAGES+=(chromium); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi

if ((${#missing[@]})); then
  echo "[setup] installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "[setup] all Debian packages present"
fi

# Blender's CC0 studio-light HDRIs (blender:NAME environments). The whole blender-data package is
# large; only its eight world panoramas are extracted into a project-local cache.
HDRI_DIR="${IBLCHECK_HDRI_DIR:-$(cd "$(dirname "$0")/.." && pwd)/.cache/blender-hdri}"
SYSTEM_HDRI=/usr/share/blender/datafiles/studiolights/world
if [[ ! -d "$SYSTEM_HDRI" && ! -f "$HDRI_DIR/sunrise.exr" ]]; then
  echo "[setup] extracting Blender HDRIs into $HDRI_DIR"
  tmp=$(mktemp -d)
  (cd "$tmp" && apt-get download blender-data >/dev/null 2>&1) || {
    $SUDO apt-get update -qq; (cd "$tmp" && apt-get download blender-data >/dev/null); }
  dpkg-deb -x "$tmp"/blender-data_*.deb "$tmp/x"
  mkdir -p "$HDRI_DIR"
  cp "$tmp/x$SYSTEM_HDRI"/*.exr "$HDRI_DIR/"
  rm -rf "$tmp"
fi
