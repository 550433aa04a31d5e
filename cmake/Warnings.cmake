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

# The asan-ubsan preset sets RASTERCHECK_SANITIZE=ON.
option(RASTERCHECK_SANITIZE "Build with AddressSanitizer and UBSan" OFF)
if(RASTERCHECK_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
