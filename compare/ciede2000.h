// A second per-pixel perceptual measure beside LDR-FLIP: the CIEDE2000 colour difference
// (CIE 142-2001; as written in Sharma, Wu and Dalal, "The CIEDE2000 color-difference
// formula: implementation notes, supplementary test data, and mathematical observations",
// Color Res. Appl. 30(1), 2005), written here from the formula, with its pooled statistics
// for report.json ("ciede2000").
//
// A frame's pixel is read as FLIP reads it (compare/flip.h): color.png's 8-bit R, G, B,
// taken as sRGB-encoded, linearized, to CIE XYZ (sRGB primaries, D65) and CIELAB relative
// to the white RGB (1, 1, 1); alpha is ignored. Unlike FLIP it looks at each pixel alone
// (no spatial filtering), so it is cheap enough to compute for every pair: pixels whose
// 8-bit colours are equal are 0 without any arithmetic.
// It does not: parametric factors other than kL = kC = kH = 1, chromatic adaptation, or
// other illuminants.
#pragma once

#include <cstdint>

#include <nlohmann/json.hpp>

#include "fixtures/frame.h"

namespace rc {

struct Lab {
  double l = 0.0;
  double a = 0.0;
  double b = 0.0;
};

// CIEDE2000 between two CIELAB colours (kL = kC = kH = 1). Symmetric in its arguments; 0
// for equal colours.
double ciede2000(const Lab& x, const Lab& y);

// CIELAB (D65, white = RGB (1, 1, 1)) of an sRGB-encoded colour with channels in [0, 1].
Lab srgbToLab(double r, double g, double b);

// Pooled CIEDE2000 over every pixel of a pair (expected against actual). The weighted_*
// values are value-weighted percentiles as FLIP's (compare/flip.h FlipStats): the smallest
// difference e such that the pixels with a difference <= e hold that fraction of the summed
// difference; 0 when every difference is 0.
struct DeltaE2000Stats {
  double mean = 0.0;
  double weighted_median = 0.0;
  double weighted_q1 = 0.0;
  double weighted_q3 = 0.0;
  double min = 0.0;
  double max = 0.0;
  std::uint64_t differing = 0;  // pixels whose 8-bit colours differ
  int worst_x = -1;             // image coordinates of max (first in row order); -1: none
  int worst_y = -1;
};

// The pooled CIEDE2000 of two frames of the same size (the caller checks the size).
DeltaE2000Stats deltaE2000Frames(const Frame& expected, const Frame& actual);

// report.json "ciede2000" (docs/reports.md); `height` gives the GL window row of worst.
nlohmann::json deltaE2000Json(const DeltaE2000Stats& stats, int height);

}  // namespace rc
