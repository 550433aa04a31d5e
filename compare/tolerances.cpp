// Tolerance defaults, overrides and the snap band: see tolerances.h and
// docs/tolerances.md (where every constant below is derived and measured).
#include "compare/tolerances.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "fixtures/errors.h"

namespace rc {

const char* toString(Status status) {
  switch (status) {
    case Status::Pass:
      return "pass";
    case Status::Warn:
      return "warn";
    case Status::Fail:
      return "fail";
    case Status::Error:
      return "error";
  }
  return "?";
}

Status worse(Status a, Status b) { return static_cast<int>(a) >= static_cast<int>(b) ? a : b; }

Status Thresholds::verdict(double measure) const {
  if (std::isnan(measure) || measure > fail) return Status::Fail;
  if (measure > warn) return Status::Warn;
  return Status::Pass;
}

Tolerances defaultTolerances(DepthFormat depth, ColorFormat color) {
  Tolerances t;
  t.depth_format = depth;
  t.color_format = color;
  // Coverage away from the band is exact on every driver: one hard pixel is a bug.
  t.visibility = {0.0, 0.0};
  switch (depth) {
    case DepthFormat::D16:
      // float32 z error (~2^-23) is far below a d16 step: only the final rounding can
      // differ, by one step.
      t.depth = {1.0, 2.0};
      break;
    case DepthFormat::D24:
    case DepthFormat::D32F:
      // A few float32 roundings of z (each ~1 step) plus the conversion rounding.
      t.depth = {4.0, 16.0};
      break;
  }
  if (color == ColorFormat::RGBA8) {
    // Both sides round to nearest; values at a rounding boundary may go either way.
    t.shading = {1.0, 2.0};
  } else {
    // float32 lighting against the reference: well under one 8-bit unit on smooth
    // surfaces; up to a few units where high exponents and interpolation meet.
    t.shading = {1.0, 4.0};
  }
  return t;
}

namespace {

void checkValue(const std::optional<double>& v, const char* what) {
  if (v && (!std::isfinite(*v) || *v < 0.0))
    throw InputError(fmt::format("tolerance: {}: must be a finite number >= 0, got {}", what, *v));
}

void applyPair(Thresholds& t, const ClassThresholds& o, const char* cls) {
  checkValue(o.warn, fmt::format("{}.warn", cls).c_str());
  checkValue(o.fail, fmt::format("{}.fail", cls).c_str());
  if (o.warn && o.fail && *o.warn > *o.fail)
    throw InputError(fmt::format("tolerance: {}: warn {} is above fail {}", cls, *o.warn, *o.fail));
  if (o.warn) {
    t.warn = *o.warn;
    if (!o.fail) t.fail = std::max(t.fail, t.warn);
  }
  if (o.fail) {
    t.fail = *o.fail;
    if (!o.warn) t.warn = std::min(t.warn, t.fail);
  }
}

}  // namespace

void applyOverrides(Tolerances& tolerances, const ToleranceOverrides& overrides) {
  applyPair(tolerances.visibility, overrides.visibility, "visibility");
  applyPair(tolerances.depth, overrides.depth, "depth");
  applyPair(tolerances.shading, overrides.shading, "shading");
  checkValue(overrides.depth_slope_factor, "depth_slope_factor");
  if (overrides.depth_slope_factor) tolerances.depth_slope_factor = *overrides.depth_slope_factor;
}

double depthStepsPerUnit(DepthFormat format) {
  switch (format) {
    case DepthFormat::D16:
      return 65535.0;
    case DepthFormat::D24:
      return 16777215.0;
    case DepthFormat::D32F:
      return 16777216.0;
  }
  return 16777215.0;
}

double snapMovePx(int subpixel_bits) {
  return std::sqrt(0.5) * std::ldexp(1.0, -std::clamp(subpixel_bits, 0, 30));
}

double snapBandPx(const Tolerances& tolerances, const BandInputs& in) {
  if (tolerances.band_px) return *tolerances.band_px;
  const double a = snapMovePx(in.expected_bits);
  const double b = snapMovePx(in.actual_bits);
  const double snap =
      in.uncertainty_is_expected ? a + b : std::max(a, b) + snapMovePx(in.uncertainty_bits);
  const double window =
      tolerances.window_error_ulps * std::ldexp(1.0, -24) * std::max({in.width, in.height, 1});
  return snap + window;
}

}  // namespace rc
