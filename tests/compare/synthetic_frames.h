// Reference-like frames built in code for the comparator's tests and benchmark: a few
// axis-aligned rectangles, each two triangles split along its diagonal, with depth planes
// and colour gradients, z-buffered, with edge_dist, depth_gap, depth_slope and gap_slope
// computed independently of the comparator (exact geometry, not pixels). Faults are then
// injected into copies.
#pragma once

#include <cstdint>
#include <vector>

#include "fixtures/frame.h"

namespace rc::testing {

struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // image coordinates (px), y down
  double z0 = 0.5;                        // depth at (x0, y0), [0, 1]
  double dzdx = 0.0;                      // depth per px
  double dzdy = 0.0;
  float rgba[4] = {0.5f, 0.5f, 0.5f, 1.0f};
  float color_dx = 0.0f;       // colour change per px in R and G
  std::uint32_t first_id = 1;  // ids first_id (upper-right triangle) and first_id + 1
};

// Renders the rectangles like a d24 z-buffer (LESS, in list order) into a reference-style
// frame with uncertainty channels; meta names backend "ref", fixture "synthetic/rects",
// subpixel_bits 8, d24, rgba32f.
Frame renderRects(int width, int height, const std::vector<Rect>& rects);

// The default scene the tests use: background, three overlapping rectangles (one steep
// in depth), at any size (coordinates scale with it).
std::vector<Rect> defaultRects(int width, int height);

// Exact d24 value of depth z stored as float, as renderers return it.
float quantizeD24(double z);

}  // namespace rc::testing
