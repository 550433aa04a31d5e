// Per-fragment operations after shading: depth quantization and test, blending and the
// colour format conversion.
//   depth: z clamped to [0, 1]; d16/d24 store q = round-half-even(z * (2^b - 1)), i.e.
//          the value q / (2^b - 1); d32f stores (float)z. llvmpipe does the same (see
//          docs/reference.md). NaN depth stores 0, as llvmpipe's conversion yields.
//   test:  LESS on the stored values (ALWAYS when the draw pass says so).
//   blend: src * a + dst * (1 - a) on all four channels (GL_SRC_ALPHA,
//          GL_ONE_MINUS_SRC_ALPHA), for rgba8 with the source clamped to [0, 1] first.
//   colour: rgba32f stores (float)c; rgba8 stores round-half-even(clamp(c, 0, 1) * 255)
//          / 255 (NaN stores 0).
// Depth buffer entries are 32-bit keys whose unsigned order is the stored values' order
// (q itself, or the bits of a non-negative float), so the test is one integer compare.
#pragma once

#include <array>
#include <bit>
#include <cstdint>

#include <glm/glm.hpp>

#include "fixtures/scene.h"
#include "reference/rounding.h"

namespace rc::ref {

// z clamped to [0, 1]; -0 and NaN become +0 (written as two selects: maxsd, minsd).
inline double clampDepth(double z) {
  z = z > 0.0 ? z : 0.0;
  return z < 1.0 ? z : 1.0;
}

// (2^b - 1) for d16/d24; for d32f the 2^24 steps per unit the depth_gap channel counts.
double depthStepsPerUnit(DepthFormat format);

// The key of a clamped depth (z01 in [0, 1], so roundHalfEvenNonNegative applies).
inline std::uint32_t depthKey(double z01, DepthFormat format) {
  switch (format) {
    case DepthFormat::D16:
      return static_cast<std::uint32_t>(roundHalfEvenNonNegative(z01 * 65535.0));
    case DepthFormat::D24:
      return static_cast<std::uint32_t>(roundHalfEvenNonNegative(z01 * 16777215.0));
    case DepthFormat::D32F:
      break;
  }
  return std::bit_cast<std::uint32_t>(static_cast<float>(z01));
}

// The stored depth a key stands for, in [0, 1].
double storedDepth(std::uint32_t key, DepthFormat format);

// out[i] = float(storedDepth(keys[i], format)) for i in [0, count): a frame's depth plane.
// For d16 and d24 it multiplies by 1 / steps instead of dividing: the product can be one
// double ulp off the quotient, but it rounds to the same float for every key of both
// formats (the quotient is never that close to a float rounding boundary; the test
// DepthKeys.PlaneIsStoredDepthForEveryKey tries all 2^16 + 2^24 keys), and a 1024 x 1024
// frame's million divisions took ~1 ms.
void storedDepthPlane(const std::uint32_t* keys, std::size_t count, DepthFormat format, float* out);

// c clamped to [0, 1]; NaN becomes 0.
inline double clampUnit(double c) {
  c = c > 0.0 ? c : 0.0;
  return c < 1.0 ? c : 1.0;
}

// float(q / 255.0) for q = 0..255: the stored rgba8 values, so that storing a channel
// needs no division. The compiler evaluates each entry with the same IEEE operations
// (one correctly rounded division, one correctly rounded conversion) as the expression
// it replaces; Determinism.GoldenFrames holds the frames to it.
inline constexpr auto kStoredUnorm8 = [] {
  std::array<float, 256> table{};
  for (int q = 0; q < 256; ++q) table[q] = static_cast<float>(q / 255.0);
  return table;
}();

// The value a colour channel is stored as: for rgba8, float(round(clamp(c) * 255) / 255).
inline float storeColor(double c, ColorFormat format) {
  if (format == ColorFormat::RGBA32F) return static_cast<float>(c);
  return kStoredUnorm8[static_cast<int>(roundHalfEvenNonNegative(clampUnit(c) * 255.0))];
}

// The exact stored value, read back for blending (for rgba8 the float holds q / 255
// rounded; q is recovered exactly).
inline double loadColor(float stored, ColorFormat format) {
  if (format == ColorFormat::RGBA32F) return stored;
  return roundHalfEvenNonNegative(static_cast<double>(stored) * 255.0) / 255.0;
}

// src * a + dst * (1 - a) per channel, a = src alpha (source clamped first for rgba8).
inline glm::dvec4 blendSourceOver(glm::dvec4 src, const glm::dvec4& dst, ColorFormat format) {
  if (format == ColorFormat::RGBA8) {
    for (int c = 0; c < 4; ++c) src[c] = clampUnit(src[c]);
  }
  const double a = src.a;
  return src * a + dst * (1.0 - a);
}

// GL's blending with a BlendFunction (glspec 4.6 17.3.6): per channel
// s * S (op) d * D, with S and D the factors of src, dst and the constant colour, min/max
// without factors. For rgba8 the source and constant are clamped to [0, 1] first (the
// destination already is); for rgba32f nothing is clamped. `src` and `dst` are what the
// fragment brings and what the buffer holds (loadColor()).
glm::dvec4 blendWithFunction(const BlendFunction& b, glm::dvec4 src, const glm::dvec4& dst,
                             ColorFormat format);

// Polygon offset's r for a depth format (the smallest difference it resolves): 1 / (2^b - 1)
// for d16 and d24; for d32f 2^(e - 23), e the exponent of the largest |z| of the polygon
// (glspec 4.6 14.6.5). `max_z`: that z (d32f only).
double minimumResolvableDepth(DepthFormat format, double max_z);

}  // namespace rc::ref
