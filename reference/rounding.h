// Round-half-to-even without libm: the one rounding rule of the reference (vertex
// snapping, depth and colour quantization), matching llvmpipe's cvtps2dq / magic-number
// conversions. Exact and identical at every optimisation level (no fast-math allowed).
#pragma once

#include <cmath>

namespace rc::ref {

// Nearest integer to v, ties to even (IEEE default rounding mode). Adding and removing
// 2^52 leaves no fraction bits, so the FPU's round-to-nearest-even does the work; values
// of magnitude >= 2^52 are already integers. NaN stays NaN.
inline double roundHalfEven(double v) {
  constexpr double kTwo52 = 4503599627370496.0;
  if (!(std::fabs(v) < kTwo52)) return v;
  return v >= 0.0 ? (v + kTwo52) - kTwo52 : (v - kTwo52) + kTwo52;
}

// The same for 0 <= v < 2^51 (depth and colour quantization), without branches.
inline double roundHalfEvenNonNegative(double v) {
  constexpr double kTwo52 = 4503599627370496.0;
  return (v + kTwo52) - kTwo52;
}

}  // namespace rc::ref
