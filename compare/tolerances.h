// The comparator's tolerances: warn/fail thresholds per class, their defaults per depth
// and colour format, fixture and command-line overrides, and the snap band inside which a
// pixel may legally go either way. Every default is derived in docs/tolerances.md.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "fixtures/scene.h"
#include "fixtures/scene_writer.h"

namespace rc {

// Verdict of one class, of a pair, of a report. Ordered: a worse status compares greater.
// NotSupported: the backend cannot render what the fixture asks (e.g. more samples than
// it has); a whole pair's status only, neither a pass nor a failure (docs/reports.md).
// Flake: a pair whose renders under `run --retries` disagreed (different bits, or one
// rendered and another did not): never a class's status.
enum class Status { Pass = 0, Warn = 1, Fail = 2, Error = 3, NotSupported = 4, Flake = 5 };
inline constexpr int kStatusCount = 6;  // Status values, for tables indexed by them
const char* toString(Status status);
Status worse(Status a, Status b);

// A measure above `warn` warns, above `fail` fails; equal to a threshold still passes.
// The per-pixel verdict of depth and shading is verdict() of the class's thresholds raised
// by the pixel's allowance (raisedBy); the comparator and `explain` both use these two.
struct Thresholds {
  double warn = 0.0;
  double fail = 0.0;
  Status verdict(double measure) const;  // NaN fails
  // Both thresholds moved up by `allowance` (a pixel's slope, texture, blend allowance):
  // warn_at = warn + allowance, fail_at = fail + allowance = fail + (warn_at - warn).
  Thresholds raisedBy(double allowance) const { return {warn + allowance, fail + allowance}; }
};

struct Tolerances {
  DepthFormat depth_format = DepthFormat::D24;
  ColorFormat color_format = ColorFormat::RGBA32F;
  // Number of hard visibility mismatches (pixels).
  Thresholds visibility;
  // Per-pixel |Za - Zb| in depth-format steps, on top of the pixel's slope allowance.
  Thresholds depth;
  // Per-pixel, per-channel |Ca - Cb| in 8-bit units, on top of the channel's shading
  // allowance; a pixel's measure is its largest channel excess.
  Thresholds shading;
  // Slope allowance of a pixel = factor * depth slope of its triangle (steps/px) * slope
  // band (px): how far a triangle's stored depth moves when its vertices move by the band.
  double depth_slope_factor = 1.0;
  // Shading allowance of a channel, in 8-bit units, with M = max(|Ca|, |Cb|) and G the
  // colour gradient (units/px):
  //   255 * shading_relative * M              float32 evaluation of the lighting
  //   + shading_slope_factor * G * band       attribute planes of snapped vertices
  // and from the reference's channels at the pixel:
  //   + (texture_weight_error + min(1, texel_reach)) * texel_alt
  //                                           linear filtering: quantised bilinear weights
  //                                           and the sample's float32 reach (texel_alt:
  //                                           the colour range of the footprints within it)
  //   + texture_rounding_units * texel_gain   linear filtering: the 8-bit filtered texel
  // (these two are 0 unless a textured material is filtered linearly),
  //   + texel_choice * texel_alt   nearest filtering, where texel_dist <= the slope band:
  //                                the sample may take the texel across the boundary (RGB)
  //   + blend_rounding_units * blend_count   rgba8: each blended fragment's 8-bit rounding
  double shading_relative = 0.0;
  double shading_slope_factor = 1.0;
  double texture_weight_error = 0.0;
  double texture_rounding_units = 0.0;
  double texel_choice = 0.0;
  double blend_rounding_units = 0.0;
  // Float error of a float32 window transform, in ulps (2^-24) of the larger image side.
  double window_error_ulps = 16.0;
  // When set, replaces the derived visibility band (px); for experiments and odd backends.
  std::optional<double> band_px;
  // When set (--flip-threshold), a pair whose mean LDR-FLIP error exceeds it fails.
  std::optional<double> flip_mean_fail;
};

// What a pair's frames say about how it was drawn, beyond the formats (frame.json).
struct DrawnWith {
  bool linear_textures = false;  // a textured material sampled with texture_filter linear
};

// The documented defaults for a pair rendered with these formats (docs/tolerances.md).
Tolerances defaultTolerances(DepthFormat depth, ColorFormat color, DrawnWith drawn = {});

// The relative error of float32 lighting at the GLSL 4.60 precisions (section 4.7.1): pow
// through exp2(s log2 x) is the worst term, ~5.7e-7 per unit of shininess s, so 2^-10
// covers exponents up to ~1700 (docs/tolerances.md).
inline constexpr double kShadingRelative = 1.0 / 1024.0;
// Linear filtering with weights of 8 fractional bits (llvmpipe; D3D's minimum subtexel
// precision): each of the two weights off by up to 2^-8, each moving the filtered value by
// up to that fraction of the footprint's contrast.
inline constexpr double kTextureWeightError = 2.0 / 256.0;
// The filtered texel kept as an 8-bit value: up to one step, times the light on it.
inline constexpr double kTextureRoundingUnits = 1.0;
// Nearest filtering: a texture coordinate within the band of a texel boundary selects
// either texel; the whole colour change the reference computed for the other texel
// (texel_alt) is allowed.
inline constexpr double kTexelChoice = 1.0;
// rgba8 blending: per blended fragment, 8-bit source and alpha (up to 1 unit together)
// and the two rounded products (up to 1 unit): 2 units, carried forward by (1 - alpha).
inline constexpr double kBlendRoundingUnits = 2.0;

// Replaces the thresholds the overrides set. A lone warn above the current fail (or a
// lone fail below the current warn) moves the other threshold with it; warn > fail when
// both are given, or a negative or non-finite value, throws InputError.
void applyOverrides(Tolerances& tolerances, const ToleranceOverrides& overrides);

// A fixture's "tolerance" block back from frame.json, where `render` records it with
// toleranceJson() (fixtures/scene_writer.h). Throws InputError naming `source` and the key
// for anything that is not a finite number >= 0.
ToleranceOverrides toleranceFromJson(const nlohmann::json& j, const std::string& source);

// What the command line can set beyond a fixture's "tolerance" block (--tolerance
// shading.relative=..., shading.slope_factor=..., visibility.band=...).
struct ExtraOverrides {
  std::optional<double> shading_relative;
  std::optional<double> shading_slope_factor;
  std::optional<double> band_px;
  std::optional<double> flip_mean_fail;  // --flip-threshold
};
struct CommandLineTolerances {
  ToleranceOverrides thresholds;
  ExtraOverrides extra;
};
// The fixture-style part as above, then the extras (finite and >= 0, else InputError).
void applyOverrides(Tolerances& tolerances, const CommandLineTolerances& overrides);

// Depth-format steps per unit of [0,1] depth: 2^b - 1 for d16/d24; d32f counts steps of
// 2^-24 (one float ulp just below 1).
double depthStepsPerUnit(DepthFormat format);

// How far a vertex (and so an edge) moves when snapped to 2^-bits px: sqrt(2)/2 * 2^-bits.
double snapMovePx(int subpixel_bits);

// The two bands of a pair, in px, from both sides' subpixel bits (docs/tolerances.md).
// edge_dist is measured to the exact (unsnapped) edges; each side draws an edge within
// snap(bits) of them, so the two sides can disagree about a pixel only within
//   visibility band = max(snap(expected), snap(actual)) + window error
// of an exact edge. A stored depth or an interpolated colour moves with the vertices of
// its own side, so the two sides' planes can be apart by
//   slope band = snap(expected) + snap(actual) + window error
// (the uncertainty frame's own snapping is irrelevant to both). window error =
// window_error_ulps * 2^-24 * max(width, height) for float32 window transforms.
struct BandInputs {
  int expected_bits = 8;
  int actual_bits = 8;
  int width = 0;
  int height = 0;
};
double snapBandPx(const Tolerances& tolerances, const BandInputs& inputs);
double slopeBandPx(const Tolerances& tolerances, const BandInputs& inputs);

}  // namespace rc
