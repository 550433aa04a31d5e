// Four doubles per vector: the lane type of the reference's batched fragment loops
// (shading_lanes.h, FragmentInterpolator::barycentricAt4). Every operation is the scalar
// IEEE operation in each lane, correctly rounded per lane, so a lane's result has the bits
// of the scalar code on the same operands whatever instructions carry it (two SSE2 halves
// on x86-64's baseline, one AVX register where the caller is compiled for it; neither has
// FMA to contract into, and the build forbids contraction anyway).
#pragma once

#include <emmintrin.h>

#include <cstdint>

namespace rc::ref {

// Lane4 values never cross a call (everything is always_inline), so the ABI note of
// -Wpsabi about passing 32-byte vectors without AVX does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// GCC/Clang vector extensions: element-wise + - * / and comparisons (all-ones lanes where
// true), `mask ? a : b` per lane.
using Lane4 = double __attribute__((vector_size(32)));
using Mask4 = std::int64_t __attribute__((vector_size(32)));

// Everything here is inlined into its caller, so that it is compiled for the caller's
// instruction set (no 32-byte vector crosses a call).
[[gnu::always_inline]] inline Lane4 splat4(double v) { return Lane4{v, v, v, v}; }
// Square roots: sqrtpd on each half (SSE2 has no wider form; under AVX the halves are
// VEX-encoded and cost about what one 256-bit square root does).
[[gnu::always_inline]] inline Lane4 sqrt4(Lane4 v) {
  const __m128d lo = _mm_sqrt_pd(__m128d{v[0], v[1]});
  const __m128d hi = _mm_sqrt_pd(__m128d{v[2], v[3]});
  return Lane4{lo[0], lo[1], hi[0], hi[1]};
}
// std::max(0.0, x) per lane: (0 < x) ? x : 0 (NaN and -0 give +0).
[[gnu::always_inline]] inline Lane4 maxZero4(Lane4 x) { return x > splat4(0.0) ? x : splat4(0.0); }

#pragma GCC diagnostic pop

}  // namespace rc::ref
