#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), then configures and builds the release
# preset. Shared by scripts/run.sh and scripts/test.sh; prints the build folder.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/setup.sh"
preset=${RASTERCHECK_PRESET:-release}
build="$root/build/$preset"
mkdir -p "$root/build"
if [[ ! -f "$build/build.ninja" ]]; then
  cmake --preset "$preset" -S "$root" >"$root/build/configure-$preset.log" 2>&1 || {
    mkdir -p "$root/build"; cat "$root/build/configure-$preset.log" >&2; exit 1; }
fi
cmake --build "$build" --parallel "$(nproc)" >&2
echo "$build"
