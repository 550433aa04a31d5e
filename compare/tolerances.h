// The comparator's tolerances: warn/fail thresholds per class, their defaults per depth
// and colour format, fixture and command-line overrides, and the snap band inside which a
// pixel may legally go either way. Every default is derived in docs/tolerances.md.
#pragma once

#include <optional>
#include <string>

#include "fixtures/scene.h"

namespace rc {

// Verdict of one class, of a pair, of a report. Ordered: a worse status compares greater.
enum class Status { Pass = 0, Warn = 1, Fail = 2, Error = 3 };
const char* toString(Status status);
Status worse(Status a, Status b);

// A measure above `warn` warns, above `fail` fails; equal to a threshold still passes.
struct Thresholds {
  double warn = 0.0;
  double fail = 0.0;
  Status verdict(double measure) const;
};

struct Tolerances {
  DepthFormat depth_format = DepthFormat::D24;
  ColorFormat color_format = ColorFormat::RGBA32F;
  // Number of hard visibility mismatches (pixels).
  Thresholds visibility;
  // Per-pixel |Za - Zb| in depth-format steps, on top of the pixel's slope allowance.
  Thresholds depth;
  // Per-pixel error in 8-bit units: the largest of |Ca - Cb| * 255 over R, G, B, A.
  Thresholds shading;
  // Slope allowance of a pixel = factor * local depth slope (steps/px) * band (px): how far
  // a triangle's stored depth moves when its vertices move by up to the band.
  double depth_slope_factor = 1.0;
  // Float error of a float32 window transform, in ulps (2^-24) of the larger image side.
  double window_error_ulps = 16.0;
  // When set, replaces the derived snap band (px); for experiments and odd backends.
  std::optional<double> band_px;
};

// The documented defaults for a pair rendered with these formats.
Tolerances defaultTolerances(DepthFormat depth, ColorFormat color);

// Replaces the thresholds the overrides set. A lone warn above the current fail (or a
// lone fail below the current warn) moves the other threshold with it; warn > fail when
// both are given, or a negative or non-finite value, throws InputError.
void applyOverrides(Tolerances& tolerances, const ToleranceOverrides& overrides);

// Depth-format steps per unit of [0,1] depth: 2^b - 1 for d16/d24; d32f counts steps of
// 2^-24 (one float ulp just below 1).
double depthStepsPerUnit(DepthFormat format);

// How far a vertex (and so an edge) moves when snapped to 2^-bits px: sqrt(2)/2 * 2^-bits.
double snapMovePx(int subpixel_bits);

// The visibility band of a pair in px: how far apart the two sides' versions of one edge
// can lie, measured from the edges the uncertainty frame's edge_dist refers to.
//   uncertainty is the expected frame: snap(a) + snap(b)
//   uncertainty is a third frame u:    max(snap(a), snap(b)) + snap(u)
// plus window_error_ulps * 2^-24 * max(width, height) for float window transforms.
struct BandInputs {
  int expected_bits = 8;
  int actual_bits = 8;
  int uncertainty_bits = 8;
  bool uncertainty_is_expected = true;
  int width = 0;
  int height = 0;
};
double snapBandPx(const Tolerances& tolerances, const BandInputs& inputs);

}  // namespace rc
