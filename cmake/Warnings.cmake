# Project-wide compile settings as INTERFACE targets the modules opt into.
# rc_warnings: the warning set every module builds with.
add_library(rc_warnings INTERFACE)
target_compile_options(rc_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow
                                             -Wno-missing-field-initializers)

# rc_strict_fp: the reference must be bit-identical on every build type, so no FMA
# contraction (GCC contracts by default) and never fast-math. -fno-math-errno is not part
# of that: it changes no value (sqrt stays IEEE sqrt, a negative argument still gives NaN),
# it only stops the compiler from keeping a libm call around to set errno, which nothing
# reads; that call and its register spills sat in every normalization of the hot loops.
add_library(rc_strict_fp INTERFACE)
target_compile_options(rc_strict_fp INTERFACE -ffp-contract=off -fno-fast-math -fno-math-errno)

# The asan-ubsan preset sets RASTERCHECK_SANITIZE=ON. Any UBSan finding stops the
# program (-fno-sanitize-recover), so that a test with undefined behaviour fails.
option(RASTERCHECK_SANITIZE "Build with AddressSanitizer and UBSan" OFF)
if(RASTERCHECK_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined -fno-sanitize-recover=all)
endif()

# RC_SANITIZER_DEFINITION: for the few sources that must know they run under the
# sanitizers (mesh_import.cpp stops at a sanitizer report from its child; tests that
# expect what a crash looks like), set on those files only so the rest of the tree is
# compiled as before.
set(RC_SANITIZER_DEFINITION "")
if(RASTERCHECK_SANITIZE)
  set(RC_SANITIZER_DEFINITION RC_SANITIZER_BUILD=1)
endif()

# The fuzz preset (clang) sets RASTERCHECK_FUZZ=ON: every library is instrumented for
# libFuzzer's coverage and built with ASan and UBSan; tests/fuzz adds the fuzz_* targets.
option(RASTERCHECK_FUZZ "Build the libFuzzer targets (clang)" OFF)
if(RASTERCHECK_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "RASTERCHECK_FUZZ needs clang (the fuzz preset sets it)")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
  set(RC_SANITIZER_DEFINITION RC_SANITIZER_BUILD=1)
endif()
