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

#include <cmath>

#include <glm/glm.hpp>

#include "reference/lanes.h"
#include "reference/viewport.h"

namespace rc::ref {

class FragmentInterpolator {
 public:
  // A zero (or non-finite) unsnapped area has no gradients: every fragment then gets the
  // vertices' mean values (only reachable when snapping gave a sliver non-zero area).
  // Without `barycentrics` only the depth plane is set up (a triangle of one colour).
  void setup(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
             bool barycentrics = true);

  // Every plane is evaluated as (f(vertex 0) + df/dy * dy) + df/dx * dx, always in this
  // order, so that the span loops, which compute the parenthesis once per row (Row), and
  // the per-pixel forms below give bit-identical values at every optimisation level.
  struct Row {
    double z = 0.0;
    double inv_w = 0.0;
    double num[3] = {0.0, 0.0, 0.0};
    double w = 0.0;  // 1 / inv_w: barycentricAt()'s quotient wherever the plane is flat in x
  };
  Row row(double y) const {
    const double dy = y - y0_;
    Row r;
    r.z = z_.rowPart(dy);
    r.inv_w = inv_w_.rowPart(dy);
    for (int k = 0; k < 3; ++k) r.num[k] = num_[k].rowPart(dy);
    r.w = 1.0 / r.inv_w;
    return r;
  }
  Row depthRow(double y) const {  // only Row::z
    Row r;
    r.z = z_.rowPart(y - y0_);
    return r;
  }
  double dx(double x) const { return x - x0_; }
  // The row `oy` px above or below r (the uncertainty channels' neighbourhood: not
  // bit-identical to row(y + oy), which sums in another order).
  Row shiftedRow(const Row& r, double oy) const {
    Row s = r;
    s.z += z_.ddy * oy;
    s.inv_w += inv_w_.ddy * oy;
    for (int k = 0; k < 3; ++k) s.num[k] += num_[k].ddy * oy;
    s.w = 1.0 / s.inv_w;
    return s;
  }
  double depthAt(const Row& r, double dx) const { return r.z + z_.ddx * dx; }
  glm::dvec3 barycentricAt(const Row& r, double dx) const {
    // The row's quotient where the denominator equals the row's (always, for an affine
    // camera: inv_w_.ddx is +-0): the same division of the same operands.
    const double den = r.inv_w + inv_w_.ddx * dx;
    const double inv = den == r.inv_w && den != 0.0 ? r.w : 1.0 / den;
    return glm::dvec3((r.num[0] + num_[0].ddx * dx) * inv, (r.num[1] + num_[1].ddx * dx) * inv,
                      (r.num[2] + num_[2].ddx * dx) * inv);
  }

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // inlined: no 32-byte vector crosses a call
  // barycentricAt() at four or eight pixels of the row (V is Lane4 or Lane8; dx per lane):
  // in each lane the same operations on the same operands, the quotient's choice as a
  // per-lane select.
  template <class V>
  [[gnu::always_inline]] void barycentricAtLanes(const Row& r, V dx, V out[3]) const {
    const V den = splatAs<V>(r.inv_w) + splatAs<V>(inv_w_.ddx) * dx;
    const MaskOf<V> row_quotient = (den == splatAs<V>(r.inv_w)) & (den != splatAs<V>(0.0));
    const V inv = selectLanes(row_quotient, splatAs<V>(r.w), splatAs<V>(1.0) / den);
    for (int k = 0; k < 3; ++k)
      out[k] = (splatAs<V>(r.num[k]) + splatAs<V>(num_[k].ddx) * dx) * inv;
  }

#pragma GCC diagnostic pop

  // Moves the depth plane by (ox, oy) px: depth at (x, y) is then the plane's value at
  // (x + ox, y + oy) (multisampling: depth at the sample, attributes at the centre).
  void shiftDepth(double ox, double oy) { z_.at_ref += z_.ddx * ox + z_.ddy * oy; }

  // Depth gradient magnitude |grad z| of the plane (window-z units per px).
  double depthSlope() const { return std::hypot(z_.ddx, z_.ddy); }
  // Its components (dz/dx, dz/dy): polygon offset's m.
  glm::dvec2 depthGradient() const { return {z_.ddx, z_.ddy}; }

  // The screen-space derivatives of the perspective-correct barycentrics `b` (as
  // barycentricAt(r, dx) returned them): d/dx in [0], d/dy in [1]. From B = N / D with N
  // and D affine: dB/dx = (dN/dx - B dD/dx) / D.
  void barycentricGradient(const Row& r, double dx, const glm::dvec3& b, glm::dvec3 out[2]) const {
    const double inv = 1.0 / (r.inv_w + inv_w_.ddx * dx);
    for (int k = 0; k < 3; ++k) {
      out[0][k] = (num_[k].ddx - b[k] * inv_w_.ddx) * inv;
      out[1][k] = (num_[k].ddy - b[k] * inv_w_.ddy) * inv;
    }
  }
  // 1 / w at the fragment (the perspective-correct denominator).
  double invWAt(const Row& r, double dx) const { return r.inv_w + inv_w_.ddx * dx; }
  // The screen gradients (d/dx, d/dy) of numerator k and of the denominator, constant over
  // the triangle: with them the gradient of an interpolated value v = sum_k a_k B_k at a
  // fragment is (sum_k a_k dN_k - v dD) / D (barycentricGradient() summed), one division
  // a fragment whatever the number of values.
  glm::dvec2 numeratorGradient(int k) const { return {num_[k].ddx, num_[k].ddy}; }
  glm::dvec2 denominatorGradient() const { return {inv_w_.ddx, inv_w_.ddy}; }

  // Window z at window point (x, y), not clamped.
  double depth(double x, double y) const { return depthAt(depthRow(y), dx(x)); }

  // Perspective-correct barycentrics of the original triangle at (x, y).
  glm::dvec3 barycentric(double x, double y) const { return barycentricAt(row(y), dx(x)); }

 private:
  struct Affine {  // plain data: setup() sets the planes it is asked for
    double at_ref;
    double ddx;
    double ddy;
    double rowPart(double dy) const { return at_ref + ddy * dy; }
  };

  double x0_;
  double y0_;
  Affine z_;
  Affine inv_w_;   // sum(l_i / w_i)
  Affine num_[3];  // sum(l_i / w_i * bary_i[k])
};

}  // namespace rc::ref
