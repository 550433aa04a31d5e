// Attribute setup: see interpolation.h.
#include "reference/interpolation.h"

#include <cmath>

namespace rc::ref {

void FragmentInterpolator::setup(const WindowVertex& v0, const WindowVertex& v1,
                                 const WindowVertex& v2, bool barycentrics) {
  x0_ = v0.x;
  y0_ = v0.y;
  const double e1x = v1.x - v0.x;
  const double e1y = v1.y - v0.y;
  const double e2x = v2.x - v0.x;
  const double e2y = v2.y - v0.y;
  const double area2 = e1x * e2y - e2x * e1y;
  const bool degenerate = !(area2 != 0.0) || !std::isfinite(area2);

  // The plane through (0, 0, f0), (e1, f1), (e2, f2) in (dx, dy, f).
  auto plane = [&](double f0, double f1, double f2) {
    Affine a{0.0, 0.0, 0.0};
    if (degenerate) {
      a.at_ref = (f0 + f1 + f2) / 3.0;
      return a;
    }
    const double d1 = f1 - f0;
    const double d2 = f2 - f0;
    a.at_ref = f0;
    a.ddx = (d1 * e2y - d2 * e1y) / area2;
    a.ddy = (d2 * e1x - d1 * e2x) / area2;
    return a;
  };

  z_ = plane(v0.z, v1.z, v2.z);
  if (!barycentrics) return;
  inv_w_ = plane(v0.inv_w, v1.inv_w, v2.inv_w);
  for (int k = 0; k < 3; ++k) {
    num_[k] = plane(v0.inv_w * v0.bary[k], v1.inv_w * v1.bary[k], v2.inv_w * v2.bary[k]);
  }
}

}  // namespace rc::ref
