// The cube root both perceptual measures need for CIELAB (compare/flip.cpp,
// compare/ciede2000.cpp), without libm's std::cbrt, which dominated their time.
#pragma once

#include <bit>
#include <cstdint>

namespace rc {

// The cube root of a normal t > 0 (CIELAB takes it above (6/29)^3 only): fdlibm's 5-bit
// first guess from the high word, then three Halley steps, each tripling the correct bits
// (5, 15, 45, then double's 53): within an ulp or two of std::cbrt.
inline double cubeRoot(double t) {
  const auto bits = std::bit_cast<std::uint64_t>(t);
  const auto hi = static_cast<std::uint32_t>(bits >> 32) / 3u + 715094163u;
  double y = std::bit_cast<double>(static_cast<std::uint64_t>(hi) << 32);
  for (int k = 0; k < 3; ++k) {
    const double y3 = y * y * y;
    y = y * (y3 + 2.0 * t) / (2.0 * y3 + t);
  }
  return y;
}

}  // namespace rc
