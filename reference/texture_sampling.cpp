// Texture sampling: see texture_sampling.h.
#include "reference/texture_sampling.h"

#include <algorithm>
#include <array>
#include <cmath>

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

}  // namespace rc::ref
