// Per-fragment operations: see fragment_ops.h.
#include "reference/fragment_ops.h"

#include <bit>

namespace rc::ref {

double depthStepsPerUnit(DepthFormat format) {
  switch (format) {
    case DepthFormat::D16: return 65535.0;
    case DepthFormat::D24: return 16777215.0;
    case DepthFormat::D32F: break;
  }
  return 16777216.0;  // one step = 2^-24 (a float ulp just below 1 is 2^-24)
}

double storedDepth(std::uint32_t key, DepthFormat format) {
  if (format == DepthFormat::D32F) {
    return std::bit_cast<float>(key);
  }
  return key / depthStepsPerUnit(format);
}

namespace {
double clampUnit(double c) {
  if (!(c > 0.0)) return 0.0;  // NaN too
  return c < 1.0 ? c : 1.0;
}
}  // namespace

float storeColor(double c, ColorFormat format) {
  if (format == ColorFormat::RGBA32F) return static_cast<float>(c);
  return static_cast<float>(roundHalfEven(clampUnit(c) * 255.0) / 255.0);
}

double loadColor(float stored, ColorFormat format) {
  if (format == ColorFormat::RGBA32F) return stored;
  // The float holds q / 255 rounded; recover q exactly.
  return roundHalfEven(static_cast<double>(stored) * 255.0) / 255.0;
}

glm::dvec4 blendSourceOver(glm::dvec4 src, const glm::dvec4& dst, ColorFormat format) {
  if (format == ColorFormat::RGBA8) {
    for (int c = 0; c < 4; ++c) src[c] = clampUnit(src[c]);
  }
  const double a = src.a;
  return src * a + dst * (1.0 - a);
}

}  // namespace rc::ref
