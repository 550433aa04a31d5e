#!/usr/bin/env bash
# Installs every Debian 12 package rastercheck needs to build, test and run.
# Idempotent and quiet when everything is already present; called by scripts/run.sh,
# scripts/test.sh and .ci/run, so a fresh machine needs no other set-up step.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  clang-format clang-tidy
  libglm-dev libgtest-dev libgmock-dev libbenchmark-dev
  libopenimageio-dev openimageio-tools
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libosmesa6-dev
  mesa-vulkan-drivers libvulkan-dev
  libassimp-dev assimp-testmodels
  nlohmann-json3-dev libcli11-dev libfmt-dev
  libpugixml-dev python3-jsonschema python3-yaml zlib1g-dev
  strace clang libclang-rt-14-dev
)
if [[ "${RASTERCHECK_SETUP_BROWSER:-1}" == 1 ]]; then
  packages+=(chromium)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "setup: installing ${missing[*]}" >&2
sudo_cmd=()
[[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq >/dev/null
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
