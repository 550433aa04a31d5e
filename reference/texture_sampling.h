// Texture sampling as GL does it for one level (no mipmaps): uv (0, 0) is the bottom-left
// corner, texel (i, j) has its centre at ((i + 0.5) / W, (j + 0.5) / H), texels are
// read as value / 255 (no sRGB decoding).
//   nearest: i = floor(u * W);
//   linear:  u * W - 0.5 = i0 + a (i0 = floor), taps i0 and i0 + 1 weighted 1 - a and a,
//            the same in v, four taps;
//   wrap:    repeat = floor-mod W, clamp = clamp-to-edge (index clamped to [0, W - 1]).
// In double. A non-finite coordinate samples texel 0 (GL leaves it undefined).
#pragma once

#include <glm/glm.hpp>

#include "fixtures/scene.h"

namespace rc::ref {

glm::dvec4 sampleTexture(const Texture& texture, const glm::dvec2& uv, TextureFilter filter,
                         TextureWrap wrap);

}  // namespace rc::ref
