// Shadow lookups: see shadow.h.
#include "reference/shadow.h"

#include <algorithm>
#include <cmath>

namespace rc::ref {
namespace {

bool fixedPoint(DepthFormat f) { return f != DepthFormat::D32F; }

int clampIndex(double floored, int size) {
  if (!(floored > 0.0)) return 0;  // NaN too
  return floored >= size - 1 ? size - 1 : static_cast<int>(floored);
}

// GL's texture comparison: 1 when r OP D holds (r the reference value, D the texel).
double compareResult(CompareFunc func, double r, double d) {
  switch (func) {
    case CompareFunc::Never:
      return 0.0;
    case CompareFunc::Less:
      return r < d ? 1.0 : 0.0;
    case CompareFunc::Equal:
      return r == d ? 1.0 : 0.0;
    case CompareFunc::LEqual:
      return r <= d ? 1.0 : 0.0;
    case CompareFunc::Greater:
      return r > d ? 1.0 : 0.0;
    case CompareFunc::NotEqual:
      return r != d ? 1.0 : 0.0;
    case CompareFunc::GEqual:
      return r >= d ? 1.0 : 0.0;
    case CompareFunc::Always:
      return 1.0;
  }
  return 1.0;
}

// The results r' OP D' can take for r' in [r_lo, r_hi], D' in [d_lo, d_hi]: the monotone
// functions take their extremes at the corners; EQUAL and NOTEQUAL go either way wherever
// the intervals meet.
void compareRange(CompareFunc func, double r_lo, double r_hi, double d_lo, double d_hi, double& lo,
                  double& hi) {
  if (func == CompareFunc::Equal || func == CompareFunc::NotEqual) {
    const bool meet = r_lo <= d_hi && d_lo <= r_hi;
    const bool single = r_lo == r_hi && d_lo == d_hi;
    if (meet && !single) {
      lo = std::min(lo, 0.0);
      hi = std::max(hi, 1.0);
      return;
    }
    const double v = compareResult(func, r_lo, d_lo);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    return;
  }
  for (double r : {r_lo, r_hi}) {
    for (double d : {d_lo, d_hi}) {
      const double v = compareResult(func, r, d);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
}

}  // namespace

ShadowCoord shadowCoord(const ShadowLookup& lookup, const glm::dvec3& p) {
  const ShadowMapData& map = *lookup.data;
  const glm::dvec4 c = map.matrix * glm::dvec4(p, 1.0);
  ShadowCoord out;
  out.in_front = c.w > 0.0;
  if (!out.in_front) return out;
  out.s = c.x / c.w;
  out.t = c.y / c.w;
  out.r = c.z / c.w - lookup.bias;
  if (fixedPoint(map.format)) out.r = std::clamp(out.r, 0.0, 1.0);
  return out;
}

double shadowFactor(const ShadowLookup& lookup, const glm::dvec3& p) {
  if (lookup.data == nullptr) return 1.0;
  const ShadowMapData& map = *lookup.data;
  const ShadowCoord c = shadowCoord(lookup, p);
  if (!c.in_front) return 1.0;
  auto at = [&](int i, int j) {
    return compareResult(lookup.compare, c.r,
                         map.depth[static_cast<std::size_t>(j) * map.width + i]);
  };
  const double u = c.s * map.width;
  const double v = c.t * map.height;
  if (lookup.filter == TextureFilter::Nearest)
    return at(clampIndex(std::floor(u), map.width), clampIndex(std::floor(v), map.height));
  const double fu = std::floor(u - 0.5);
  const double fv = std::floor(v - 0.5);
  const double a = std::isfinite(fu) ? (u - 0.5) - fu : 0.0;
  const double b = std::isfinite(fv) ? (v - 0.5) - fv : 0.0;
  const int i0 = clampIndex(fu, map.width);
  const int i1 = clampIndex(fu + 1.0, map.width);
  const int j0 = clampIndex(fv, map.height);
  const int j1 = clampIndex(fv + 1.0, map.height);
  return (1.0 - a) * (1.0 - b) * at(i0, j0) + a * (1.0 - b) * at(i1, j0) +
         (1.0 - a) * b * at(i0, j1) + a * b * at(i1, j1);
}

ShadowRange shadowRange(const ShadowLookup& lookup, const glm::dvec3& p, double ds, double dt,
                        double dr) {
  ShadowRange out;
  if (lookup.data == nullptr) return out;
  const ShadowMapData& map = *lookup.data;
  const ShadowCoord c = shadowCoord(lookup, p);
  if (!c.in_front) return out;  // w's sign near 0 is not weighed (the map's camera plane)
  const double u = c.s * map.width;
  const double v = c.t * map.height;
  const double du = ds;
  const double dv = dt;
  // The texels the lookup may read: nearest, those its coordinate may fall in; linear,
  // every texel of the footprints it may have.
  const double shift = lookup.filter == TextureFilter::Nearest ? 0.0 : 0.5;
  const int i_first = clampIndex(std::floor(u - shift - du), map.width);
  const int j_first = clampIndex(std::floor(v - shift - dv), map.height);
  const int extra = lookup.filter == TextureFilter::Nearest ? 0 : 1;
  const int i_last = clampIndex(std::floor(u - shift + du) + extra, map.width);
  const int j_last = clampIndex(std::floor(v - shift + dv) + extra, map.height);
  out.i = clampIndex(std::floor(u - shift), map.width);
  out.j = clampIndex(std::floor(v - shift), map.height);
  double r_lo = c.r - dr;
  double r_hi = c.r + dr;
  if (fixedPoint(map.format)) {
    r_lo = std::clamp(r_lo, 0.0, 1.0);
    r_hi = std::clamp(r_hi, 0.0, 1.0);
  }
  out.lo = 1.0;
  out.hi = 0.0;
  for (int j = j_first; j <= j_last; ++j) {
    for (int i = i_first; i <= i_last; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * map.width + i;
      const double d = map.depth[k];
      const double d_lo = map.lo.empty() ? d : map.lo[k];
      const double d_hi = map.hi.empty() ? d : map.hi[k];
      compareRange(lookup.compare, r_lo, r_hi, d_lo, d_hi, out.lo, out.hi);
    }
  }
  return out;
}

}  // namespace rc::ref
