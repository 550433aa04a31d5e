// Per-fragment operations: see fragment_ops.h.
#include "reference/fragment_ops.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace rc::ref {

double depthStepsPerUnit(DepthFormat format) {
  switch (format) {
    case DepthFormat::D16:
      return 65535.0;
    case DepthFormat::D24:
      return 16777215.0;
    case DepthFormat::D32F:
      break;
  }
  return 16777216.0;  // one step = 2^-24 (a float ulp just below 1 is 2^-24)
}

double storedDepth(std::uint32_t key, DepthFormat format) {
  if (format == DepthFormat::D32F) {
    return std::bit_cast<float>(key);
  }
  return key / depthStepsPerUnit(format);
}

void storedDepthPlane(const std::uint32_t* keys, std::size_t count, DepthFormat format,
                      float* out) {
  if (format == DepthFormat::D32F) {
    for (std::size_t i = 0; i < count; ++i) out[i] = std::bit_cast<float>(keys[i]);
    return;
  }
  const double per_step = 1.0 / depthStepsPerUnit(format);
  // Integer keys are below 2^24: through int32 the conversion vectorizes (cvtdq2pd).
  for (std::size_t i = 0; i < count; ++i)
    out[i] = static_cast<float>(static_cast<std::int32_t>(keys[i]) * per_step);
}

}  // namespace rc::ref

namespace rc::ref {
namespace {

// Factor `f` for channel c (0..2 colour, 3 alpha) of a blend.
double blendFactor(BlendFactor f, int c, const glm::dvec4& src, const glm::dvec4& dst,
                   const glm::dvec4& constant) {
  switch (f) {
    case BlendFactor::Zero:
      return 0.0;
    case BlendFactor::One:
      return 1.0;
    case BlendFactor::SrcColor:
      return src[c];
    case BlendFactor::OneMinusSrcColor:
      return 1.0 - src[c];
    case BlendFactor::DstColor:
      return dst[c];
    case BlendFactor::OneMinusDstColor:
      return 1.0 - dst[c];
    case BlendFactor::SrcAlpha:
      return src.a;
    case BlendFactor::OneMinusSrcAlpha:
      return 1.0 - src.a;
    case BlendFactor::DstAlpha:
      return dst.a;
    case BlendFactor::OneMinusDstAlpha:
      return 1.0 - dst.a;
    case BlendFactor::ConstantColor:
      return constant[c];
    case BlendFactor::OneMinusConstantColor:
      return 1.0 - constant[c];
    case BlendFactor::ConstantAlpha:
      return constant.a;
    case BlendFactor::OneMinusConstantAlpha:
      return 1.0 - constant.a;
    case BlendFactor::SrcAlphaSaturate:
      return c == 3 ? 1.0 : std::min(src.a, 1.0 - dst.a);
  }
  return 0.0;
}

double blendEquation(BlendEquation e, double s, double fs, double d, double fd) {
  switch (e) {
    case BlendEquation::Add:
      return s * fs + d * fd;
    case BlendEquation::Subtract:
      return s * fs - d * fd;
    case BlendEquation::ReverseSubtract:
      return d * fd - s * fs;
    case BlendEquation::Min:
      return std::min(s, d);
    case BlendEquation::Max:
      return std::max(s, d);
  }
  return s;
}

}  // namespace

glm::dvec4 blendWithFunction(const BlendFunction& b, glm::dvec4 src, const glm::dvec4& dst,
                             ColorFormat format) {
  glm::dvec4 constant = b.constant;
  if (format == ColorFormat::RGBA8) {
    for (int c = 0; c < 4; ++c) {
      src[c] = clampUnit(src[c]);
      constant[c] = clampUnit(constant[c]);
    }
  }
  glm::dvec4 out;
  for (int c = 0; c < 4; ++c) {
    const bool alpha = c == 3;
    const BlendFactor fs = alpha ? b.src_alpha : b.src;
    const BlendFactor fd = alpha ? b.dst_alpha : b.dst;
    out[c] = blendEquation(alpha ? b.equation_alpha : b.equation, src[c],
                           blendFactor(fs, c, src, dst, constant), dst[c],
                           blendFactor(fd, c, src, dst, constant));
  }
  return out;
}

double minimumResolvableDepth(DepthFormat format, double max_z) {
  switch (format) {
    case DepthFormat::D16:
      return 1.0 / 65535.0;
    case DepthFormat::D24:
      return 1.0 / 16777215.0;
    case DepthFormat::D32F:
      break;
  }
  int e = 0;
  std::frexp(std::fabs(max_z), &e);  // |z| = m 2^e, m in [0.5, 1): exponent e - 1
  return std::ldexp(1.0, e - 1 - 23);
}

}  // namespace rc::ref
