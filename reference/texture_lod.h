// Level of detail (glspec 4.6 section 8.14): the scale factor, lambda, the level(s) a
// minifying filter reads and the blend between two levels, on the chain of
// fixtures/mipmaps.h. In double, in the scalar style of texture_sampling.h, which samples
// one level.
//   rho    = max(sqrt(ux^2 + vx^2), sqrt(uy^2 + vy^2)), u, v in level-0 texels, their
//            derivatives exact at the fragment (docs/reference.md "Textures: level of
//            detail": not from a 2x2 quad, which is a driver's choice);
//   lambda = clamp(log2(rho) + clamp(lod_bias, -kMaxLodBias, kMaxLodBias), min_lod, max_lod);
//   lambda <= 0: magnification, the mag filter on level 0 (GL 4.6 core; older specs
//            switched at 0.5 for a linear mag filter with nearest_mipmap_*); else the
//            min filter:
//            nearest, linear: level 0; *_mipmap_nearest: level 0 for lambda <= 0.5, q past
//            q + 0.5, else ceil(lambda + 0.5) - 1; *_mipmap_linear: levels floor(lambda)
//            and the next weighted 1 - frac and frac (level q alone from lambda >= q),
//            q the last level.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "fixtures/scene.h"

namespace rc::ref {

// GL clamps the bias to +-GL_MAX_TEXTURE_LOD_BIAS, at least 2; Mesa's drivers give 16.
inline constexpr double kMaxLodBias = 16.0;

struct LodState {
  MinFilter min = MinFilter::Nearest;
  TextureFilter mag = TextureFilter::Nearest;
  TextureWrap wrap = TextureWrap::Repeat;
  double bias = 0.0;
  double min_lod = -1000.0;
  double max_lod = 1000.0;
};
LodState lodState(const RenderState& s);

// GL's scale factor of the derivatives (texels of level 0 per px).
double scaleFactor(const glm::dvec2& d_dx, const glm::dvec2& d_dy);
// lambda of a scale factor (bias and clamps applied; -inf bias-free for rho 0 clamps to
// min_lod).
double lodOf(double rho, const LodState& s);

struct LodSample {
  glm::dvec4 color{0.0};
  bool magnified = false;
  int level0 = 0;
  int level1 = 0;
  double weight = 0.0;  // of level1
};
LodSample sampleAtLod(const std::vector<const Texture*>& chain, const glm::dvec2& uv, double lambda,
                      const LodState& s);

// Per channel, the largest minus the smallest texel value any lambda in [lo, hi] and any
// sample position within `shift` (uv units, per axis) of uv gives: lambda at the ends of the
// interval and at every point inside where the result's formula changes (c, each level
// boundary k + 0.5 and each integer k), each with the positions uv, uv +- shift.
glm::dvec4 lodRange(const std::vector<const Texture*>& chain, const glm::dvec2& uv, double lo,
                    double hi, const glm::dvec2& shift, const LodState& s);

}  // namespace rc::ref
