// Texture sampling as GL does it for one level (no mipmaps): uv (0, 0) is the bottom-left
// corner, texel (i, j) has its centre at ((i + 0.5) / W, (j + 0.5) / H), texels are
// read as value / 255 (no sRGB decoding).
//   nearest: i = floor(u * W);
//   linear:  u * W - 0.5 = i0 + a (i0 = floor), taps i0 and i0 + 1 weighted 1 - a and a,
//            the same in v, four taps;
//   wrap:    repeat = floor-mod W, clamp = clamp-to-edge (index clamped to [0, W - 1]),
//            mirrored repeat = floor-mod 2W, indices W .. 2W - 1 read 2W - 1 - index.
// In double. A non-finite coordinate samples texel 0 (GL leaves it undefined).
#pragma once

#include <glm/glm.hpp>

#include "fixtures/scene.h"

namespace rc::ref {

// The largest Texture::uncertainty of the texels a lookup at uv may read (nearest: the
// texel and its eight neighbours, which a sample near a boundary may take; linear: the 2x2
// footprint and the ring around it), 0 for textures without one.
double texelValueReach(const Texture& texture, const glm::dvec2& uv, TextureFilter filter,
                       TextureWrap wrap);
glm::dvec4 sampleTexture(const Texture& texture, const glm::dvec2& uv, TextureFilter filter,
                         TextureWrap wrap);

// Float32 rounding of a texture coordinate in a driver, as a fraction of the magnitudes it
// is computed from (16 ulps; docs/tolerances.md "texel_dist"): the perspective-correct
// interpolation (two attribute planes and a division), the scaling by the texture size
// and the plane evaluation relative to a far origin each round a few times.
inline constexpr double kTexelCoordinateReach = 0x1p-20;

// One axis of a nearest-filtered sample, in texels: the coordinate (u * W), its
// screen-space gradient magnitude (texels/px), and how far float rounding may move it.
struct TexelAxis {
  double coord = 0.0;
  double gradient = 0.0;
  double reach = 0.0;
};

// The nearest filter's discontinuities around a sample: the screen distance (px) the
// sample would have to move, beyond `reach`, for another texel to be chosen (capped at
// `cap`), and the texels across the nearest boundary of each axis closer than `cap` px
// (in s, in t, and across both when both are).
struct TexelChoice {
  double dist_px = 1.0;
  glm::dvec4 chosen{0.0};
  int alternatives = 0;
  glm::dvec4 alt[3] = {glm::dvec4(0.0), glm::dvec4(0.0), glm::dvec4(0.0)};
};
TexelChoice nearestTexelChoice(const Texture& texture, const TexelAxis& s, const TexelAxis& t,
                               TextureWrap wrap, double cap);

// Per channel, the largest minus the smallest texel of every footprint the linear filter
// may read when the sample at uv moves by up to reach_s, reach_t texels (with 0, 0 its own
// 2x2 footprint): columns floor(u W - 0.5 - reach_s) to floor(u W - 0.5 + reach_s) + 1, rows
// alike, wrapped (every one once they span the texture) or clamped as `wrap` says. `whole`
// (the range of the whole texture) answers when more than kMaxReachTexels would be visited.
inline constexpr long kMaxReachTexels = 256;
glm::dvec4 linearReachRange(const Texture& texture, const glm::dvec2& uv, TextureWrap wrap,
                            double reach_s, double reach_t, const glm::dvec4& whole);

// Per channel, the largest minus the smallest texel of the whole texture.
glm::dvec4 textureRange(const Texture& texture);

}  // namespace rc::ref
