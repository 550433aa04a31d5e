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
    case Status::NotSupported:
      return "not_supported";
    case Status::Flake:
      return "flake";
  }
  return "?";
}

Status worse(Status a, Status b) {
  if (a == Status::NotSupported) return b;  // never a class's status: no order to keep
  if (b == Status::NotSupported) return a;
  return static_cast<int>(a) >= static_cast<int>(b) ? a : b;
}

Status Thresholds::verdict(double measure) const {
  if (std::isnan(measure) || measure > fail) return Status::Fail;
  if (measure > warn) return Status::Warn;
  return Status::Pass;
}

Tolerances defaultTolerances(DepthFormat depth, ColorFormat color, DrawnWith drawn) {
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
      // A few float32 roundings of z near 1 (each up to one 2^-24 step) plus the
      // conversion rounding: 4; fail where no plausible evaluation order reaches: 16.
      t.depth = {4.0, 16.0};
      break;
  }
  t.shading_relative = kShadingRelative;
  if (color == ColorFormat::RGBA8) {
    // Both sides round to nearest: a float difference below one unit rounds to at most
    // one unit, so 2 units cannot come from rounding.
    t.shading = {1.0, 1.0};
    t.blend_rounding_units = kBlendRoundingUnits;
  } else {
    // Above the float32 allowance: warn beyond 1/64 unit (absolute error of dot products
    // near zero); fail beyond half a unit, where it changes an 8-bit image.
    t.shading = {1.0 / 64.0, 0.5};
  }
  if (drawn.linear_textures) {
    t.texture_weight_error = kTextureWeightError;
    t.texture_rounding_units = kTextureRoundingUnits;
  }
  // Only where the reference's texel_alt says a nearest-filtered sample lies near a texel
  // boundary; zero everywhere else.
  t.texel_choice = kTexelChoice;
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

void applyOverrides(Tolerances& tolerances, const CommandLineTolerances& overrides) {
  applyOverrides(tolerances, overrides.thresholds);
  const ExtraOverrides& x = overrides.extra;
  checkValue(x.shading_relative, "shading.relative");
  checkValue(x.shading_slope_factor, "shading.slope_factor");
  checkValue(x.band_px, "visibility.band");
  checkValue(x.flip_mean_fail, "--flip-threshold");
  if (x.flip_mean_fail) tolerances.flip_mean_fail = *x.flip_mean_fail;
  if (x.shading_relative) tolerances.shading_relative = *x.shading_relative;
  if (x.shading_slope_factor) tolerances.shading_slope_factor = *x.shading_slope_factor;
  if (x.band_px) tolerances.band_px = *x.band_px;
}

ToleranceOverrides toleranceFromJson(const nlohmann::json& j, const std::string& source) {
  auto bad = [&](const std::string& path, const std::string& what) {
    return InputError(fmt::format("{}: tolerance{}: {}", source, path, what));
  };
  if (!j.is_object()) throw bad("", "must be an object");
  ToleranceOverrides o;
  auto number = [&](const nlohmann::json& v, const std::string& path) {
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0.0)
      throw bad(path, fmt::format("must be a finite number >= 0, got {}", v.dump()));
    return v.get<double>();
  };
  for (const auto& [cls, value] : j.items()) {
    ClassThresholds* t = cls == "visibility" ? &o.visibility
                         : cls == "depth"    ? &o.depth
                         : cls == "shading"  ? &o.shading
                                             : nullptr;
    if (!t) throw bad("." + cls, "unknown class (visibility, depth, shading)");
    if (!value.is_object()) throw bad("." + cls, "must be an object");
    for (const auto& [key, v] : value.items()) {
      const std::string path = fmt::format(".{}.{}", cls, key);
      if (key == "warn")
        t->warn = number(v, path);
      else if (key == "fail")
        t->fail = number(v, path);
      else if (cls == "depth" && key == "slope_factor")
        o.depth_slope_factor = number(v, path);
      else
        throw bad(path, "unknown key");
    }
  }
  return o;
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

namespace {
double windowErrorPx(const Tolerances& tolerances, const BandInputs& in) {
  return tolerances.window_error_ulps * std::ldexp(1.0, -24) * std::max({in.width, in.height, 1});
}
}  // namespace

double snapBandPx(const Tolerances& tolerances, const BandInputs& in) {
  if (tolerances.band_px) return *tolerances.band_px;
  return std::max(snapMovePx(in.expected_bits), snapMovePx(in.actual_bits)) +
         windowErrorPx(tolerances, in);
}

double slopeBandPx(const Tolerances& tolerances, const BandInputs& in) {
  return snapMovePx(in.expected_bits) + snapMovePx(in.actual_bits) + windowErrorPx(tolerances, in);
}

}  // namespace rc
