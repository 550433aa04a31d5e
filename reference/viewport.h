// Perspective divide and viewport transform (GL conventions): window x, y in pixels with
// the origin at the bottom-left corner (y up), pixel centres at +0.5, window z = depth
// range [0, 1]. In double; the viewport is the whole image.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "reference/clipper.h"

namespace rc::ref {

// Plain data without default values (the renderer keeps arrays of them on the stack for
// every triangle); toWindow() sets every field.
struct WindowVertex {
  double x;
  double y;
  double z;         // window depth, z_ndc * 0.5 + 0.5
  double inv_w;     // 1 / w_clip, for perspective-correct interpolation
  glm::dvec3 bary;  // w.r.t. the original triangle (from the clipper)
};

inline WindowVertex toWindow(const ClipVertex& c, int width, int height) {
  const double inv_w = 1.0 / c.clip.w;
  WindowVertex v;
  v.x = (c.clip.x * inv_w * 0.5 + 0.5) * width;
  v.y = (c.clip.y * inv_w * 0.5 + 0.5) * height;
  v.z = c.clip.z * inv_w * 0.5 + 0.5;
  v.inv_w = inv_w;
  v.bary = c.bary;
  return v;
}

// How far (px) a float32 implementation may put the window position of `c`, from its clip
// coordinates' error bound: x_w = (x / w * 0.5 + 0.5) * width moves by
// width / 2 * (e_x + |x / w| e_w) / |w| (y alike), as a distance.
inline double windowErrorPx(const ClipVertex& c, int width, int height) {
  const double aw = std::fabs(c.clip.w);
  const double ex = 0.5 * width * (c.err.x + std::fabs(c.clip.x / c.clip.w) * c.err.w) / aw;
  const double ey = 0.5 * height * (c.err.y + std::fabs(c.clip.y / c.clip.w) * c.err.w) / aw;
  return std::hypot(ex, ey);
}

// The same for window depth (z_w = z / w * 0.5 + 0.5, in [0, 1] units): how far a float32
// implementation's vertex transform may put it (docs/tolerances.md "Vertex precision").
inline double windowDepthError(const ClipVertex& c) {
  return 0.5 * (c.err.z + std::fabs(c.clip.z / c.clip.w) * c.err.w) / std::fabs(c.clip.w);
}

}  // namespace rc::ref
