// Level of detail: see texture_lod.h.
#include "reference/texture_lod.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference/texture_sampling.h"

namespace rc::ref {
namespace {

bool mipmapped(MinFilter f) { return f != MinFilter::Nearest && f != MinFilter::Linear; }
bool nearestMip(MinFilter f) {
  return f == MinFilter::NearestMipmapNearest || f == MinFilter::LinearMipmapNearest;
}
TextureFilter levelFilter(MinFilter f) {
  return f == MinFilter::Linear || f == MinFilter::LinearMipmapNearest ||
                 f == MinFilter::LinearMipmapLinear
             ? TextureFilter::Linear
             : TextureFilter::Nearest;
}
// GL 4.6 core (8.14, 8.15): lambda <= 0 is magnification. (GL 1.x-2.x used 0.5 for a
// linear mag filter with nearest_mipmap_*; Mesa's drivers use 0, as the core profile says.)
double switchPoint(const LodState&) { return 0.0; }

}  // namespace

LodState lodState(const RenderState& s) {
  return {minFilter(s), magFilter(s), s.texture_wrap, s.lod_bias, s.min_lod, s.max_lod};
}

double scaleFactor(const glm::dvec2& d_dx, const glm::dvec2& d_dy) {
  return std::max(std::sqrt(d_dx.x * d_dx.x + d_dx.y * d_dx.y),
                  std::sqrt(d_dy.x * d_dy.x + d_dy.y * d_dy.y));
}

double lodOf(double rho, const LodState& s) {
  const double bias = std::clamp(s.bias, -kMaxLodBias, kMaxLodBias);
  double lambda = std::log2(rho) + bias;  // -inf for rho 0; NaN for a NaN rho
  if (std::isnan(lambda)) lambda = s.min_lod;
  return std::clamp(lambda, s.min_lod, s.max_lod);
}

LodSample sampleAtLod(const std::vector<const Texture*>& chain, const glm::dvec2& uv, double lambda,
                      const LodState& s) {
  LodSample out;
  if (lambda <= switchPoint(s) || !mipmapped(s.min)) {
    out.magnified = lambda <= switchPoint(s);
    const TextureFilter filter = out.magnified ? s.mag : levelFilter(s.min);
    out.color = sampleTexture(*chain[0], uv, filter, s.wrap);
    return out;
  }
  const int q = static_cast<int>(chain.size()) - 1;
  const TextureFilter filter = levelFilter(s.min);
  if (nearestMip(s.min)) {
    int d = 0;
    if (lambda > q + 0.5) {
      d = q;
    } else if (lambda > 0.5) {
      d = static_cast<int>(std::ceil(lambda + 0.5)) - 1;
    }
    out.level0 = out.level1 = d;
    out.color = sampleTexture(*chain[static_cast<std::size_t>(d)], uv, filter, s.wrap);
    return out;
  }
  if (lambda >= q) {
    out.level0 = out.level1 = q;
    out.color = sampleTexture(*chain[static_cast<std::size_t>(q)], uv, filter, s.wrap);
    return out;
  }
  const double d1 = std::floor(lambda);
  out.level0 = static_cast<int>(d1);
  out.level1 = out.level0 + 1;
  out.weight = lambda - d1;
  const glm::dvec4 t1 =
      sampleTexture(*chain[static_cast<std::size_t>(out.level0)], uv, filter, s.wrap);
  const glm::dvec4 t2 =
      sampleTexture(*chain[static_cast<std::size_t>(out.level1)], uv, filter, s.wrap);
  out.color = (1.0 - out.weight) * t1 + out.weight * t2;
  return out;
}

glm::dvec4 lodRange(const std::vector<const Texture*>& chain, const glm::dvec2& uv, double lo,
                    double hi, const glm::dvec2& shift, const LodState& s) {
  std::vector<double> lambdas = {lo, hi};
  const double q = static_cast<double>(chain.size()) - 1.0;
  // Just either side of every point where the result's formula changes (a jump for the
  // mag/min switch and nearest-mip boundaries, a kink for the linear blends).
  constexpr double kSide = 1e-9;
  auto add = [&](double x) {
    for (double v : {x - kSide, x, x + kSide})
      if (v > lo && v < hi) lambdas.push_back(v);
  };
  add(switchPoint(s));
  for (double k = std::max(0.0, std::floor(lo)); k <= std::min(q, std::ceil(hi)) + 1.0; ++k) {
    add(k);
    add(k + 0.5);
  }
  glm::dvec4 mn(std::numeric_limits<double>::infinity());
  glm::dvec4 mx(-std::numeric_limits<double>::infinity());
  const glm::dvec2 offsets[5] = {
      {0.0, 0.0}, {shift.x, 0.0}, {-shift.x, 0.0}, {0.0, shift.y}, {0.0, -shift.y}};
  for (double lambda : lambdas) {
    if (!std::isfinite(lambda)) continue;
    for (const glm::dvec2& o : offsets) {
      const glm::dvec4 c = sampleAtLod(chain, uv + o, lambda, s).color;
      mn = glm::min(mn, c);
      mx = glm::max(mx, c);
    }
  }
  if (!(mx.x >= mn.x)) return glm::dvec4(0.0);
  return mx - mn;
}

}  // namespace rc::ref
