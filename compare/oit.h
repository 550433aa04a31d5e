// How far a pair's blended colour is from the exact order-independent answer: when the
// expected frame is `ref:abuffer` (frame.json "abuffer"), the colour error over every
// pixel that holds blended fragments, whatever its visibility class, and which triangles
// the sorted-triangle draw order blends out of depth order (report.json "oit").
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/tolerances.h"
#include "fixtures/frame.h"

namespace rc {

struct OitPair {
  std::uint32_t near_id = 0;  // nearer at the pixels, but drawn first (so blended under)
  std::uint32_t far_id = 0;   // farther, but drawn after it
  std::uint64_t pixels = 0;
  int first_x = -1;  // the first such pixel, image coordinates
  int first_y = -1;
};

struct OitStats {
  std::uint64_t blended_pixels = 0;   // pixels the exact answer blends fragments at
  std::uint64_t unsorted_pixels = 0;  // of those, where the draw order is not depth order
  // Pixels whose colour differs from the exact answer by more than the shading warn
  // threshold (largest channel, 8-bit units), counted at every pixel, and the error there.
  std::uint64_t pixels = 0;
  double max_abs = 0.0;   // largest channel error over all pixels (8-bit units)
  double mean_abs = 0.0;  // mean of the per-pixel largest channel error over blended pixels
  int worst_x = -1;       // image coordinates of max_abs (first in row order)
  int worst_y = -1;
  double threshold = 0.0;             // the warn threshold `pixels` counts above
  std::uint64_t pairs_total = 0;      // out-of-order triangle pairs (frame.json lists <= 64)
  std::vector<OitPair> out_of_order;  // most pixels first
};

// Empty unless `expected` is an A-buffer frame (its meta has "abuffer").
std::optional<OitStats> compareOit(const Frame& expected, const Frame& actual,
                                   const Tolerances& tolerances);

// report.json "oit" (docs/reports.md).
nlohmann::json oitJson(const OitStats& stats, int height);

}  // namespace rc
