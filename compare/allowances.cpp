// The allowances a pixel's error is held to, from the reference's uncertainty channels:
// depth slope and reach, depth ties, blended pixels, and the shading terms (relative,
// gradient, texture, blending, coverage); formulas derived in docs/tolerances.md.
#include <algorithm>
#include <cmath>
#include <limits>

#include "compare/compare_internal.h"
#include "compare/slopes.h"

namespace rc {
namespace {
Thresholds heldTo(const Thresholds& base, const std::vector<float>& recorded, std::size_t i) {
  // The map holds the raised warn only where the error exceeded the base warn (0
  // elsewhere); within it the pixel passes whatever its allowance, and the base applies.
  const double warn_at = std::max<double>(recorded[i], base.warn);
  return base.raisedBy(warn_at - base.warn);
}
}  // namespace

Thresholds depthThresholdsAt(const ClassMaps& maps, std::size_t i, const Tolerances& tolerances) {
  return heldTo(tolerances.depth, maps.depth_tolerance, i);
}

Thresholds shadingThresholdsAt(const ClassMaps& maps, std::size_t i, const Tolerances& tolerances) {
  return heldTo(tolerances.shading, maps.shading_tolerance, i);
}

}  // namespace rc

namespace rc::detail {

// ---- Depth: slope allowance (docs/tolerances.md) ----

// The depth slope (steps/px) the reference recorded for the fragment whose depth it
// stored at pixel i; 0 without uncertainty channels (nothing is excused then).
double Comparator::depthSlope(std::size_t i) const {
  const double s = have_uncertainty_ ? static_cast<double>(u_.depth_slope[i]) : 0.0;
  return std::isnan(s) ? 0.0 : s;
}

// How far float32 vertex transforms may move the window depth of pixel i's fragments
// (steps, the reference's depth_reach); 0 without uncertainty channels, NaN excuses nothing.
double Comparator::depthReach(std::size_t i) const {
  const double r = have_uncertainty_ ? static_cast<double>(u_.depth_reach[i]) : 0.0;
  return std::isnan(r) ? 0.0 : r;
}

// The depth allowance of pixel i on top of the warn or fail threshold, for a fragment of
// depth gradient `slope` (steps/px): where snapping moves its plane, plus its vertices'
// float32 reach (docs/tolerances.md section 2).
double Comparator::depthAllowance(std::size_t i, double slope) const {
  double allowance = depth_slope_band_ * slope + depthReach(i);
  // Polygon offset: another implementation's r moves the offset by the spread of r times
  // |units| x r_min (NaN or 0 where nothing offset was tested).
  if (have_uncertainty_) {
    const double offset = u_.offset_steps[i] * r_.depth.offset_r_spread;
    if (offset > 0.0) allowance += offset;
  }
  return allowance;
}

// Whether the reference's depth comparisons at pixel i could legally go the other way,
// so that the driver shows id b where the reference shows a. Each fragment's stored
// depth may be off by its tolerance (fail + allowance) in either direction; two
// fragments closer than the sum may swap. The slope is the steeper fragment's of the
// comparisons that decided the pixel (gap_slope). Against the clear depth (missing,
// extra: primitive or background), only the fragment's own tolerance: the clear value
// is exact on both sides.
bool Comparator::ambiguousByDepth(std::size_t i, std::uint32_t a, std::uint32_t b) const {
  return a != 0 && b != 0 ? static_cast<double>(u_.depth_gap[i]) <=
                                2.0 * (tol_.depth.fail + depthAllowance(i, u_.gap_slope[i]))
                          : static_cast<double>(u_.clear_gap[i]) <=
                                tol_.depth.fail + depthAllowance(i, u_.clear_slope[i]);
}

// Whether the fragments blended under the top one at pixel i may legally differ: a
// blended pixel near a polygon edge (another fragment may or may not cover it) or with
// a blended fragment's depth test within the tolerance of flipping. Its depth and colour
// are then not held to their tolerances (docs/tolerances.md, "Blended pixels"). `k` is
// describing(x, y, i): driver against driver, where the reference shows another
// primitive at i, its channels there describe that primitive's fragments, not the blend
// under the expected one; those at k, where it shows the expected primitive, do.
bool Comparator::blendUncertain(std::size_t i, std::size_t k) const {
  return blendUncertainAt(i) || (k != i && blendUncertainAt(k));
}
bool Comparator::blendUncertainAt(std::size_t i) const {
  if (!have_uncertainty_ || !(u_.blend_count[i] > 0.0f)) return false;
  return static_cast<double>(u_.edge_dist[i]) <= band_ ||
         static_cast<double>(u_.blend_gap[i]) <=
             2.0 * (tol_.depth.fail + depthAllowance(i, u_.blend_slope[i]));
}

// Whether the driver may legally hold the clear depth at pixel i where the expected frame
// holds a fragment's, with the same primitive seen: a visible fragment that writes no depth
// over a fragment GL leaves to the driver (a line's end, a point's side, a polygon edge
// within the band: edge_dist). The driver that leaves that fragment out keeps what was
// there before, and only the clear depth is known to have been there (an earlier fragment's
// would need a channel of its own). The other way round, a fragment only the driver drew,
// is not excused: nothing here knows the depth it should have (zink's zero-area triangles in
// polygon mode store a wrong one: docs/results/findings.md). docs/tolerances.md, "Blended
// pixels".
bool Comparator::optionalFragmentLeftOut(std::size_t i, std::size_t k) const {
  if (!have_uncertainty_ || std::isnan(clear_steps_) || !(u_.edge_dist[k] <= band_) ||
      i >= a_.depth.size())
    return false;
  const double rounding = scale_.quantized ? 1.0 : 0.0;
  return std::fabs(scale_(a_.depth[i]) - clear_steps_) <= rounding;
}

// The pixel whose uncertainty channels describe the expected frame's fragment at pixel
// (x, y), index i: i itself, unless the uncertainty frame is another frame (driver
// against driver) that shows another primitive there. Then a neighbour (8-connected)
// where it shows the expected primitive: a primitive's depth slope is one plane's
// gradient, the same at every pixel it covers, and its vertices' reach changes by a
// fraction of a step across a pixel. i when no neighbour shows it (no allowance is known).
std::size_t Comparator::describing(int x, int y, std::size_t i) const {
  if (!have_uncertainty_ || &u_ == &e_ || u_.id[i] == e_.id[i]) return i;
  const std::uint32_t want = e_.id[i];
  std::size_t found = i;
  detail::forEachNeighbour(e_, x, y, [&](std::size_t j, int, int) {
    if (u_.id[j] != want) return true;
    found = j;
    return false;
  });
  return found;
}

// dz is over warn: check it against the pixel's slope allowance.
__attribute__((noinline)) void Comparator::depthOverBase(int x, int y, std::size_t i, double dz) {
  DepthStats& d = r_.depth;
  const std::size_t k = describing(x, y, i);
  const double slope = depthSlope(k);  // NaN excuses nothing
  const double allow = depthAllowance(k, slope);
  const Thresholds at = tol_.depth.raisedBy(allow);
  if (maps_) maps_->depth_tolerance[i] = static_cast<float>(at.warn);
  d.max_slope = std::max(d.max_slope, slope);
  const double excess = dz - at.warn;
  if (excess <= 0.0) return;
  if (blendUncertain(i, k) || optionalFragmentLeftOut(i, k)) {
    ++d.blend_uncertain;
    return;
  }
  ++d.over_tolerance;
  if (at.verdict(dz) == Status::Fail) ++d.over_fail;  // dz is finite here
  depth_worst_.offer(excess, i, dz, allow);
}

__attribute__((noinline)) void Comparator::depthNonFinite(std::size_t i) {
  ++r_.depth.nonfinite;
  ++r_.depth.over_tolerance;
  ++r_.depth.over_fail;
  depth_worst_.offer(kInf, i, std::numeric_limits<double>::quiet_NaN(), 0.0);
}

// ---- Shading: relative, gradient and texture allowances (docs/tolerances.md) ----

// With `neighbourhood` false, only the terms that need no neighbours (a lower bound).
Comparator::ShadingExcess Comparator::shadingExcess(int x, int y, std::size_t i, const float* d,
                                                    bool neighbourhood) const {
  const float* pa = &e_.color[i * 4];
  const float* pb = &a_.color[i * 4];
  detail::ColourNeighbourhood around;
  if (neighbourhood) {
    around = detail::colourNeighbourhood(e_, x, y);
    // Driver against driver: the surface's colour gradient is also what the uncertainty
    // frame (the reference) shows around the pixel, where it shows the same primitive.
    // A driver's own neighbourhood can miss it: where its ids differ from the reference's
    // around the pixel (legal, ambiguous edges), it finds fewer same-primitive neighbours
    // and a flatter gradient, so an allowance the comparison with the reference gives
    // would be missing here. The larger of the two per channel.
    if (have_uncertainty_ && &u_ != &e_ && u_.id[i] == e_.id[i] && !u_.color.empty()) {
      const detail::ColourNeighbourhood reference = detail::colourNeighbourhood(u_, x, y);
      for (int c = 0; c < 4; ++c)
        around.gradient[c] = std::max(around.gradient[c], reference.gradient[c]);
    }
  }
  ShadingExcess out;
  // The colour's own sensitivity to its vertices' positions (shade_reach, units per px,
  // from the reference's attribute planes): where the neighbours show a flatter gradient
  // than the surface has, as around a sliver whose pixels have no same-primitive
  // neighbour, it is the gradient the slope band moves (docs/tolerances.md (b)).
  double plane = 0.0;
  // And how far float32 interpolation may turn a short interpolated normal
  // (normal_reach, units; docs/tolerances.md (a)).
  double normal = 0.0;
  if (have_uncertainty_ && u_.id[i] == e_.id[i]) {
    const double r = u_.shade_reach[i];
    plane = std::isnan(r) ? 0.0 : r;
    const double n = u_.normal_reach[i];
    normal = std::isnan(n) ? 0.0 : n;
  }
  // What the reference knows at the pixel: with nearest filtering, a sample within the
  // band of a texel boundary may take the texel across it (texel_alt, RGB only); in
  // rgba8 every blended fragment may round differently (blend_count).
  double texel = 0.0;
  double filtering = 0.0;
  double blends = 0.0;
  if (have_uncertainty_) {
    if (tol_.texel_choice > 0.0 && static_cast<double>(u_.texel_dist[i]) <= texel_band_)
      texel = tol_.texel_choice * u_.texel_alt[i];
    // Linear filtering: quantised weights, and a sample moved by float32 interpolation
    // (texel_reach, texels), move the value by a fraction of the colour range of the
    // footprints it may read (texel_alt); the 8-bit filtered texel by a unit times its
    // light. (NaN reach: excuses nothing.)
    const double reach = std::isnan(u_.texel_reach[i]) ? 0.0 : u_.texel_reach[i];
    filtering = (tol_.texture_weight_error + std::min(1.0, reach)) * u_.texel_alt[i] +
                tol_.texture_rounding_units * u_.texel_gain[i];
    blends = tol_.blend_rounding_units * u_.blend_count[i];
  }
  for (int c = 0; c < 4; ++c) {
    const double m = std::max(std::fabs(pa[c]), std::fabs(pb[c]));
    const double gradient =
        c < 3 ? std::max(static_cast<double>(around.gradient[c]), plane) : around.gradient[c];
    out.allowances[c] = shade_relative_units_ * m + shade_slope_band_ * gradient + blends +
                        (c < 3 ? texel + filtering + normal : 0.0) + coverage_allowance_;
  }
  for (int c = 0; c < 4; ++c) {
    const double excess = d[c] - out.allowances[c];
    if (excess > out.excess) {
      out.excess = excess;
      out.channel = c;
      out.allowance = out.allowances[c];
    }
    const double without = excess + (c < 3 ? texel : 0.0);
    out.excess_without_texel = std::max(out.excess_without_texel, without);
  }
  return out;
}

// The pixel's largest channel error is over warn: check it against its allowance.
__attribute__((noinline)) void Comparator::shadingOver(int x, int y, std::size_t i,
                                                       const float* d) {
  const double warn = tol_.shading.warn;
  // The terms without neighbours are a lower bound of the allowance: often enough (unless
  // the texel term is needed: then whether the rest covers it decides the count).
  if (!maps_) {
    const ShadingExcess lower = shadingExcess(x, y, i, d, false);
    if (lower.excess <= warn && lower.excess_without_texel <= warn) return;
  }
  const ShadingExcess s = shadingExcess(x, y, i, d, true);
  if (maps_) {
    // The threshold the pixel's largest channel error is held to: exceeding it by k is
    // exceeding warn by k in the deciding channel (the channels' allowances differ).
    const float e = std::max(std::max(d[0], d[1]), std::max(d[2], d[3]));
    maps_->shading_tolerance[i] = static_cast<float>(tol_.shading.raisedBy(e - s.excess).warn);
    if (i == maps_->describe_pixel) maps_->describe_allowances = s.allowances;
  }
  // The excess is already net of the channel's allowance: the base thresholds judge it
  // (never NaN: a NaN channel excess is never the largest).
  const Status verdict = tol_.shading.verdict(s.excess);
  if (verdict == Status::Pass) {
    if (s.excess_without_texel > warn) ++r_.shading.texel_choice;
    return;
  }
  if (blendUncertain(i, describing(x, y, i))) {
    ++r_.shading.blend_uncertain;
    return;
  }
  ++r_.shading.over_tolerance;
  if (verdict == Status::Fail) ++r_.shading.over_fail;
  shade_worst_.offer(s.excess, i, d[s.channel], s.allowance);
}

__attribute__((noinline)) void Comparator::shadingNonFinite(std::size_t i) {
  ++r_.shading.nonfinite;
  ++r_.shading.over_tolerance;
  ++r_.shading.over_fail;
  shade_worst_.offer(kInf, i, std::numeric_limits<double>::quiet_NaN(), 0.0);
}

}  // namespace rc::detail
