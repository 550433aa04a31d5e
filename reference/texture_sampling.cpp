// Texture sampling: see texture_sampling.h.
#include "reference/texture_sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace rc::ref {
namespace {

// value / 255 for every byte, computed by division once (identical to dividing per use).
const std::array<double, 256>& unorm8Table() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = i / 255.0;
    return t;
  }();
  return table;
}

// Texel index for an integer-valued (floored) coordinate, wrapped into [0, size).
int wrapIndex(double floored, int size, TextureWrap wrap) {
  if (!std::isfinite(floored)) return 0;
  if (wrap == TextureWrap::Clamp) return static_cast<int>(std::clamp(floored, 0.0, size - 1.0));
  // Integer floor-mod where the coordinate fits: the same index as the double formula
  // below (its quotient cannot round onto an integer below 2^31), at a fraction of the cost
  // (the double path is a division and a libm floor; lines sample textures 147 times a
  // fragment for their colour slack).
  const bool small = std::fabs(floored) < 2147483648.0;
  if (wrap == TextureWrap::MirroredRepeat) {
    if (small) {
      const long long period = 2LL * size;
      long long k = static_cast<long long>(floored) % period;
      if (k < 0) k += period;
      return static_cast<int>(k < size ? k : period - 1 - k);
    }
    // Period 2 size: indices size .. 2 size - 1 mirror back onto size - 1 .. 0.
    const double period = 2.0 * size;
    const double m = floored - period * std::floor(floored / period);
    const int k = std::clamp(static_cast<int>(m), 0, 2 * size - 1);
    return k < size ? k : 2 * size - 1 - k;
  }
  if (small) {
    // Powers of two (most textures): two's complement masking is the floor-mod.
    if ((size & (size - 1)) == 0)
      return static_cast<int>(static_cast<long long>(floored) & (size - 1));
    const long long k = static_cast<long long>(floored) % size;
    return static_cast<int>(k < 0 ? k + size : k);
  }
  const double m = floored - size * std::floor(floored / size);  // floor-mod, in [0, size]
  return std::clamp(static_cast<int>(m), 0, size - 1);           // m == size only by rounding
}

glm::dvec4 texel(const Texture& t, int i, int j) {
  const auto& table = unorm8Table();
  const std::size_t base = 4 * (static_cast<std::size_t>(j) * t.width + i);
  return glm::dvec4(table[t.rgba[base]], table[t.rgba[base + 1]], table[t.rgba[base + 2]],
                    table[t.rgba[base + 3]]);
}

}  // namespace

double texelValueReach(const Texture& texture, const glm::dvec2& uv, TextureFilter filter,
                       TextureWrap wrap) {
  if (texture.uncertainty.empty()) return 0.0;
  const bool linear = filter == TextureFilter::Linear;
  const double fs = std::floor(uv.x * texture.width - (linear ? 0.5 : 0.0));
  const double ft = std::floor(uv.y * texture.height - (linear ? 0.5 : 0.0));
  double out = 0.0;
  for (int dj = -1; dj <= (linear ? 2 : 1); ++dj) {
    for (int di = -1; di <= (linear ? 2 : 1); ++di) {
      const int i = wrapIndex(fs + di, texture.width, wrap);
      const int j = wrapIndex(ft + dj, texture.height, wrap);
      out =
          std::max(out, static_cast<double>(
                            texture.uncertainty[static_cast<std::size_t>(j) * texture.width + i]));
    }
  }
  return out;
}

glm::dvec4 sampleTexture(const Texture& texture, const glm::dvec2& uv, TextureFilter filter,
                         TextureWrap wrap) {
  const double s = uv.x * texture.width;
  const double t = uv.y * texture.height;
  if (filter == TextureFilter::Nearest) {
    return texel(texture, wrapIndex(std::floor(s), texture.width, wrap),
                 wrapIndex(std::floor(t), texture.height, wrap));
  }
  const double fs = std::floor(s - 0.5);
  const double ft = std::floor(t - 0.5);
  const double a = std::isfinite(fs) ? (s - 0.5) - fs : 0.0;
  const double b = std::isfinite(ft) ? (t - 0.5) - ft : 0.0;
  const int i0 = wrapIndex(fs, texture.width, wrap);
  const int i1 = wrapIndex(fs + 1.0, texture.width, wrap);
  const int j0 = wrapIndex(ft, texture.height, wrap);
  const int j1 = wrapIndex(ft + 1.0, texture.height, wrap);
  return (1.0 - a) * (1.0 - b) * texel(texture, i0, j0) + a * (1.0 - b) * texel(texture, i1, j0) +
         (1.0 - a) * b * texel(texture, i0, j1) + a * b * texel(texture, i1, j1);
}

namespace {

// One axis: the distance (px, `cap` when farther) to the nearest texel boundary the wrap
// mode has, and the texel index on its other side. Under clamp-to-edge only the
// boundaries inside the texture (1 .. size-1) change the texel; under repeat every
// integer does.
struct AxisChoice {
  double dist_px;
  int chosen;
  int other;
};
AxisChoice axisChoice(const TexelAxis& a, int size, TextureWrap wrap, double cap) {
  const int chosen = wrapIndex(std::floor(a.coord), size, wrap);
  AxisChoice out{cap, chosen, chosen};
  if (!std::isfinite(a.coord)) return out;
  double k = std::round(a.coord);
  if (wrap == TextureWrap::Clamp) {
    if (size < 2) return out;
    k = std::clamp(k, 1.0, size - 1.0);
  }
  const double d = std::fabs(a.coord - k);
  double px = 0.0;
  if (d > a.reach) px = a.gradient > 0.0 ? (d - a.reach) / a.gradient : cap;
  if (!(px < cap)) return out;
  out.dist_px = px;
  // The texel on the other side of boundary k: k itself when the sample is below it.
  out.other = wrapIndex(a.coord < k ? k : k - 1.0, size, wrap);
  if (out.other == chosen) out.other = wrapIndex(a.coord < k ? k - 1.0 : k, size, wrap);
  return out;
}

// The texel indices [first, last] of one axis that footprints within `reach` texels of
// coordinate `coord` (u * size) read: under repeat before wrapping (nullopt when they span
// the axis), under clamp already clamped into [0, size - 1].
std::optional<std::pair<double, double>> reachSpan(double coord, double reach, int size,
                                                   TextureWrap wrap) {
  const double first = std::floor(coord - 0.5 - reach);
  const double last = std::floor(coord - 0.5 + reach) + 1.0;
  if (std::isnan(first) || std::isnan(last)) return std::nullopt;
  if (wrap == TextureWrap::Clamp)
    return std::pair{std::clamp(first, 0.0, size - 1.0), std::clamp(last, 0.0, size - 1.0)};
  if (!std::isfinite(first) || !std::isfinite(last) || last - first + 1.0 >= size)
    return std::nullopt;
  return std::pair{first, last};
}

}  // namespace

glm::dvec4 linearReachRange(const Texture& texture, const glm::dvec2& uv, TextureWrap wrap,
                            double reach_s, double reach_t, const glm::dvec4& whole) {
  const auto cols = reachSpan(uv.x * texture.width, reach_s, texture.width, wrap);
  const auto rows = reachSpan(uv.y * texture.height, reach_t, texture.height, wrap);
  const double ncols = cols ? cols->second - cols->first + 1.0 : texture.width;
  const double nrows = rows ? rows->second - rows->first + 1.0 : texture.height;
  if (ncols * nrows > static_cast<double>(kMaxReachTexels)) return whole;
  glm::dvec4 lo(std::numeric_limits<double>::infinity());
  glm::dvec4 hi(-std::numeric_limits<double>::infinity());
  for (double r = 0; r < nrows; ++r) {
    const int j = rows ? wrapIndex(rows->first + r, texture.height, wrap) : static_cast<int>(r);
    for (double c = 0; c < ncols; ++c) {
      const int i = cols ? wrapIndex(cols->first + c, texture.width, wrap) : static_cast<int>(c);
      const glm::dvec4 v = texel(texture, i, j);
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
  }
  return hi - lo;
}

glm::dvec4 textureRange(const Texture& texture) {
  if (texture.width <= 0 || texture.height <= 0) return glm::dvec4(0.0);
  glm::dvec4 lo(std::numeric_limits<double>::infinity());
  glm::dvec4 hi(-std::numeric_limits<double>::infinity());
  for (int j = 0; j < texture.height; ++j)
    for (int i = 0; i < texture.width; ++i) {
      const glm::dvec4 v = texel(texture, i, j);
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
  return hi - lo;
}

TexelChoice nearestTexelChoice(const Texture& texture, const TexelAxis& s, const TexelAxis& t,
                               TextureWrap wrap, double cap) {
  const AxisChoice cs = axisChoice(s, texture.width, wrap, cap);
  const AxisChoice ct = axisChoice(t, texture.height, wrap, cap);
  TexelChoice out;
  out.dist_px = std::min(cs.dist_px, ct.dist_px);
  out.chosen = texel(texture, cs.chosen, ct.chosen);
  const bool in_s = cs.dist_px < cap && cs.other != cs.chosen;
  const bool in_t = ct.dist_px < cap && ct.other != ct.chosen;
  if (in_s) out.alt[out.alternatives++] = texel(texture, cs.other, ct.chosen);
  if (in_t) out.alt[out.alternatives++] = texel(texture, cs.chosen, ct.other);
  if (in_s && in_t) out.alt[out.alternatives++] = texel(texture, cs.other, ct.other);
  return out;
}

}  // namespace rc::ref
