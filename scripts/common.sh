#!/usr/bin/env bash
# Shared set-up for the two README commands: installs the Debian 12 packages that are missing,
# then configures and builds crepuscular in ./build (Release, warnings as errors): everything, or one
# target (CREP_BUILD_TARGET).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

CREP_PACKAGES=(
  build-essential cmake pkg-config
  libglm-dev libeigen3-dev libopenexr-dev doctest-dev libstb-dev
  libepoxy-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
  glslang-tools nlohmann-json3-dev zlib1g-dev
  glslc spirv-tools spirv-cross
  mesa-vulkan-drivers libvulkan-dev vulkan-validationlayers libshaderc-dev glslang-dev
)

crep_install_packages() {
  local missing=()
  for p in "${CREP_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ((${#missing[@]})); then
    echo "crep: installing ${missing[*]}" >&2
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
}

# crep_build DIR [cmake configure arguments...]; CREP_BUILD_TARGET=NAME builds that target only (the render
# command builds the `crep` tool, not the test suite).
crep_build() {
  local dir=${1:-build}
  shift || true
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "$@"
  cmake --build "$dir" -j "$(nproc)" ${CREP_BUILD_TARGET:+--target "$CREP_BUILD_TARGET"}
}
