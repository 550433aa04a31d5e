#!/usr/bin/env bash
# Builds the asan-ubsan preset (Debug, AddressSanitizer + UBSan, any finding fatal) and
# runs under it the unit tests, the CLI tests and a sample of the GL tests. .ci/sanitize
# (a CI job of its own, not .ci/run: docs/reliability.md "CI" gives the times) calls it.
# Both selections run even when the first fails; the exit status is 1 if either failed.
# Extra arguments go to ctest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/setup.sh"
build="$root/build/asan-ubsan"
mkdir -p "$root/build"
if [[ ! -f "$build/build.ninja" ]]; then
  cmake --preset asan-ubsan -S "$root" >"$root/build/configure-asan-ubsan.log" 2>&1 || {
    cat "$root/build/configure-asan-ubsan.log" >&2; exit 1; }
fi
# Only what the two selections below run (the conformance and benchmark programs are not
# built here).
cmake --build "$build" --parallel "$(nproc)" --target rastercheck test_fixtures test_frame_io \
  test_fuzz_regressions test_compare test_compare_frames test_cli test_gl test_gl_cli test_debug >&2

# Leaks in the GL drivers and image libraries loaded at run time are theirs (LLVM's JIT
# in llvmpipe keeps its allocations to exit); our own code is checked by ASan's other
# checks and by the leak check of the unit tests, which load no driver.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/scripts/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
cd "$build"
# Unit tests of every module that needs no driver, the CLI end to end (every command; the
# kill tests, which repeat one command dozens of times under strace, run in the release
# build only), the debug tools' tests; then one GL test of each kind: the backend and
# its process rules, the command line with a driver, injected faults, a few rendering
# cases (clipping at the near plane, blending, textures, Gouraud).
status=0
ctest --output-on-failure --no-tests=error --parallel "$(nproc)" \
  -L 'fixtures|compare|cli|debug' -E '^(DebugGl|Conformance|Catalog|Mutation)|Reliability\.Killing' "$@" ||
  status=1
ctest --output-on-failure --no-tests=error --parallel "$(nproc)" \
  -R '^(GlBackend|GlProcess|GlCli|GlFault)\.|^GlRaster\.(TriangleCrossingTheNearPlane|AlphaBlendOverOpaque|NearestTexelCentres)$|^GlShading\.(GouraudInterpolatesVertexColours|TextureMultipliesAmbientAndDiffuseNotSpecular)$' "$@" ||
  status=1
exit $status
