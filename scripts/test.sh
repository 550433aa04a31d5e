#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs every test through
# CTest. Extra arguments go to ctest (e.g. -L gl, -R Loader).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mkdir -p "$root/build"
build=$(bash "$root/scripts/build.sh")
cd "$build"
# The tests' own user cache (fixtures/shared_cache.h): their results do not depend on what
# ~/.cache/rastercheck holds.
export RASTERCHECK_CACHE_DIR="$build/test-user-cache"
exec ctest --output-on-failure --no-tests=error --parallel "$(nproc)" "$@"
