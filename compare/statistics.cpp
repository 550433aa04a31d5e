// The statistics and verdicts of a pair once its pixels are counted (Comparator::finish):
// per class the counts, maxima, means, percentiles and worst pixel, then the pair's status.
#include <algorithm>
#include <cmath>

#include "compare/compare_internal.h"

namespace rc {

std::uint64_t NonFiniteCounts::total() const {
  std::uint64_t t = 0;
  for (std::size_t c = 0; c < nan.size(); ++c) t += nan[c] + inf[c];
  return t;
}

}  // namespace rc

namespace rc::detail {

PixelRef Comparator::pixelAt(std::size_t i) const {
  return {static_cast<int>(i % e_.width), static_cast<int>(i / e_.width)};
}

void Comparator::finish() {
  depth_hot_.flush();
  shade_hot_.flush();

  VisibilityStats& v = r_.visibility;
  auto count = [&](PixelClass c) { return class_counts_[static_cast<int>(c)]; };
  v.missing = count(PixelClass::MissingAmbiguous) + count(PixelClass::MissingHard);
  v.extra = count(PixelClass::ExtraAmbiguous) + count(PixelClass::ExtraHard);
  v.wrong_primitive = count(PixelClass::WrongAmbiguous) + count(PixelClass::WrongHard);
  v.missing_hard = count(PixelClass::MissingHard);
  v.extra_hard = count(PixelClass::ExtraHard);
  v.wrong_primitive_hard = count(PixelClass::WrongHard);
  v.hard = v.missing_hard + v.extra_hard + v.wrong_primitive_hard;
  v.mismatched = v.missing + v.extra + v.wrong_primitive;
  v.ambiguous = v.mismatched - v.hard;
  v.uncertainty_available = have_uncertainty_;
  v.samples = e_.samples;
  v.mismatched_samples = sample_mismatches_;
  v.status = tol_.visibility.verdict(static_cast<double>(v.hard));
  if (vis_worst_.any) {
    v.worst = pixelAt(vis_worst_.index);
    v.worst_edge_dist = vis_worst_.value;
  }

  DepthStats& d = r_.depth;
  d.compared = vis_match_;
  const std::uint64_t depth_finite = d.compared - d.nonfinite;
  d.max_steps = depth_max_;
  d.mean_steps = depth_finite ? depth_sum_ / static_cast<double>(depth_finite) : 0.0;
  d.p99_steps = d.histogram.percentile(0.99, depth_max_);
  if (depth_worst_.any) {
    d.worst = pixelAt(depth_worst_.index);
    d.worst_steps = depth_worst_.value;
    d.worst_allowance = depth_worst_.allowance;
  } else if (depth_max_ > 0.0) {  // all equal: no worst pixel
    d.worst = pixelAt(depth_max_at_);
    d.worst_steps = depth_max_;
    d.worst_allowance = depthAllowance(depth_max_at_, depthSlope(depth_max_at_));
  }
  d.status = d.over_fail ? Status::Fail : d.over_tolerance ? Status::Warn : Status::Pass;

  ShadingStats& s = r_.shading;
  s.compared = e_.multisampled() ? shade_compared_ + s.nonfinite : vis_match_;
  s.depth_tied = shade_skipped_;
  const std::uint64_t shade_finite = s.compared - s.nonfinite;
  s.max_abs = shade_max_;
  for (int c = 0; c < 4; ++c) s.max_abs_rgba[c] = shade_max_rgba_[c];
  if (shade_finite > 0) {
    const double values = 4.0 * static_cast<double>(shade_finite);
    s.mean_abs = shade_sum_ / values;
    s.rmse = std::sqrt(shade_sq_ / values);
  }
  s.psnr_db = s.rmse > 0.0 ? std::min(kPsnrCapDb, 20.0 * std::log10(255.0 / s.rmse)) : kPsnrCapDb;
  s.p99_abs = s.histogram.percentile(0.99, shade_max_);
  if (shade_worst_.any) {
    s.worst = pixelAt(shade_worst_.index);
    s.worst_abs = shade_worst_.value;
    s.worst_allowance = shade_worst_.allowance;
  } else if (shade_max_ > 0.0f) {
    s.worst = pixelAt(shade_max_at_);
    float dk[4];
    for (int c = 0; c < 4; ++c)
      dk[c] = colorError(e_.color[shade_max_at_ * 4 + c], a_.color[shade_max_at_ * 4 + c]);
    const int c = static_cast<int>(std::max_element(dk, dk + 4) - dk);
    s.worst_abs = dk[c];
    s.worst_allowance = shadingExcess(s.worst.x, s.worst.y, shade_max_at_, dk, true).allowances[c];
  }
  s.status = s.over_fail ? Status::Fail : s.over_tolerance ? Status::Warn : Status::Pass;

  r_.status = worse(v.status, worse(d.status, s.status));
}

}  // namespace rc::detail
