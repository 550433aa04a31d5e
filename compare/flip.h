// A perceptual error per pixel: LDR-FLIP (Andersson, Nilsson, Akenine-Moeller, Oskarsson,
// Astrom, Fairchild, "FLIP: A Difference Evaluator for Alternating Images", HPG 2020),
// written here from the paper's formulas, and its pooled statistics for report.json.
//
// Input: two RGB images whose values are display-encoded (sRGB) in [0, 1]. A frame's
// colour is what the framebuffer holds, shown without any sRGB encoding step, so FLIP
// sees each frame as the 8-bit picture color.png (and the report's expected.png /
// actual.png) shows: flipImageOf() clamps R, G, B to [0, 1] (NaN as 0), rounds to 8 bits
// as color.png does, and FLIP reads those values as sRGB-encoded (linearizing them with
// the sRGB transfer function). Alpha is ignored: the pixel as shown, opaque. This is what
// NVIDIA's FLIP tool computes when given the two PNGs.
// It does not: HDR-FLIP, or viewing conditions other than those given.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/tolerances.h"
#include "fixtures/frame.h"

namespace rc {

// Viewing conditions: the paper's default, a 0.7 m wide 3840 px monitor seen from 0.7 m.
struct FlipViewing {
  double distance_m = 0.7;
  double monitor_width_m = 0.7;
  double monitor_width_px = 3840.0;
  // Pixels per degree of visual angle: distance * (px / width) * pi / 180 (~67.02).
  double pixelsPerDegree() const;
};

// An image of `width` x `height` pixels, RGB, sRGB-encoded values in [0, 1], top row first.
struct FlipImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;
};

// Per-pixel LDR-FLIP error in [0, 1], index y * width + x. Throws InputError when the
// sizes differ or the buffers do not match them.
std::vector<float> flipError(const FlipImage& reference, const FlipImage& test,
                             const FlipViewing& viewing = {});

// The colour of a frame as FLIP reads it: color.png's 8-bit values (see the file comment).
FlipImage flipImageOf(const Frame& frame);

// Pooled statistics of a FLIP error map. weighted_* are value-weighted percentiles: the
// smallest error e such that the pixels with error <= e hold at least that fraction of the
// summed error (weighted_median: half; q1/q3: a quarter, three quarters), the pooling the
// FLIP tool reports so that a few large errors are not hidden by many zero pixels; 0 when
// every error is 0.
struct FlipStats {
  Status status = Status::Pass;  // Fail when mean > threshold (Tolerances::flip_mean_fail)
  double mean = 0.0;
  double weighted_median = 0.0;
  double weighted_q1 = 0.0;
  double weighted_q3 = 0.0;
  double max = 0.0;
  double min = 0.0;
  std::optional<double> threshold;
  double ppd = 0.0;  // pixels per degree used
};
FlipStats poolFlip(const std::vector<float>& error);

// FLIP of the frames' colours (expected as the reference), pooled, with the verdict of
// tolerances.flip_mean_fail; the per-pixel map into *map when given.
FlipStats flipFrames(const Frame& expected, const Frame& actual, const Tolerances& tolerances,
                     std::vector<float>* map = nullptr);

// report.json "flip" (docs/reports.md).
nlohmann::json flipJson(const FlipStats& stats);

// The colour map of flip_heat.png: magma, as the paper shows FLIP maps.
inline constexpr const char* kFlipColorMap = "magma";

// flip_heat.png's pixels (RGB, 8 bits): each error in [0, 1] through the magma colour map
// (OpenImageIO's, sampled at 256 points; error e takes entry round(255 e)).
std::vector<std::uint8_t> flipHeatRgb(const std::vector<float>& error);

}  // namespace rc
