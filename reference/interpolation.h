// Attribute setup for one rasterized (fan) triangle: the window-z plane and the
// perspective-correct barycentric coordinates w.r.t. the ORIGINAL triangle, both from
// the UNSNAPPED window vertices, in double, evaluated at pixel centres.
//
// Screen-space barycentrics l_i of the fan triangle are affine in (x, y); with q_i =
// l_i / w_i, the original triangle's perspective-correct coordinates are
// B = sum(q_i * bary_i) / sum(q_i) (the lecture notes' perspective-correct interpolation,
// applied to the barycentrics themselves). Numerator and denominator are affine too, so
// each is set up once as value-at-vertex-0 plus x and y gradients. Window z is affine in
// screen space (a plane). Pixels the snapped triangle covers outside the unsnapped one
// extrapolate, as GL does. It does not rasterize, shade or quantize.
#pragma once

#include <glm/glm.hpp>

#include "reference/viewport.h"

namespace rc::ref {

class FragmentInterpolator {
 public:
  // A zero (or non-finite) unsnapped area has no gradients: every fragment then gets the
  // vertices' mean values (only reachable when snapping gave a sliver non-zero area).
  void setup(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2);

  // Window z at window point (x, y), not clamped.
  double depth(double x, double y) const { return z_(x - x0_, y - y0_); }

  // Perspective-correct barycentrics of the original triangle at (x, y).
  glm::dvec3 barycentric(double x, double y) const {
    const double dx = x - x0_;
    const double dy = y - y0_;
    const double inv = 1.0 / inv_w_(dx, dy);
    return glm::dvec3(num_[0](dx, dy) * inv, num_[1](dx, dy) * inv, num_[2](dx, dy) * inv);
  }

 private:
  // f(dx, dy) = f(vertex 0) + dy * df/dy + dx * df/dx, always in this order, so every
  // caller (render, trace, -O0, -O2) gets bit-identical values.
  struct Affine {
    double at_ref = 0.0;
    double ddx = 0.0;
    double ddy = 0.0;
    double operator()(double dx, double dy) const { return (at_ref + ddy * dy) + ddx * dx; }
  };

  double x0_ = 0.0;
  double y0_ = 0.0;
  Affine z_;
  Affine inv_w_;   // sum(l_i / w_i)
  Affine num_[3];  // sum(l_i / w_i * bary_i[k])
};

}  // namespace rc::ref
