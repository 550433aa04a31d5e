// The uncertainty channels: what the reference knows about where another conforming
// rasterizer may legally differ from it.
//   edge_dist: per pixel, the distance in pixels from the pixel centre to the nearest
//     boundary edge SEGMENT (unsnapped window coordinates) of any rasterized polygon,
//     capped at 1. Polygons are the clipped triangles (their boundary, not the internal
//     fan diagonals), after culling, plus culled or zero-area ones whose cull decision a
//     snap of another implementation could flip (cullCouldFlip()). Computed in a band
//     around each edge, so the cost follows the perimeter, not the area.
//   depth_gap: per pixel, the two smallest window depths among ALL fragments that covered
//     it (any primitive, passing the depth test or not); gap = z2 - z1 in steps of the
//     depth format (d16/d24: * (2^b - 1); d32f: / 2^-24), +inf with fewer than two.
// It does not decide coverage or visibility.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "fixtures/scene.h"
#include "reference/rasterizer.h"
#include "reference/viewport.h"

namespace rc::ref {

class DepthGapTracker {
 public:
  void reset(std::size_t pixels) { slots_.assign(pixels, Slot{}); }
  void add(std::size_t index, double z) {
    Slot& s = slots_[index];
    if (z < s.first) {
      s.second = s.first;
      s.first = z;
    } else if (z < s.second) {
      s.second = z;
    }
  }
  // (z2 - z1) in steps of the format; +inf when fewer than two fragments.
  float gapSteps(std::size_t index, DepthFormat format) const;

 private:
  struct Slot {
    double first = std::numeric_limits<double>::infinity();
    double second = std::numeric_limits<double>::infinity();
  };
  std::vector<Slot> slots_;
};

// Twice the signed area (> 0 counter-clockwise) and the perimeter of a window polygon.
double polygonArea2(const WindowVertex* polygon, int count);
double polygonPerimeter(const WindowVertex* polygon, int count);

// Moving each vertex by up to this many pixels (half a step at 3 subpixel bits: coarser
// than any driver measured, softpipe snaps to 1/16) is how much another implementation's
// snapping may disagree with ours.
inline constexpr double kSnapDisagreementPx = 1.0 / 16.0;

// Whether snapping within kSnapDisagreementPx could change the sign of the polygon's
// area: |2A| <= 2 * d * perimeter + 4 * d^2, since moving vertex i by d changes 2A by at
// most d * |v(i+1) - v(i-1)| <= d * (|e(i-1)| + |e(i)|).
bool cullCouldFlip(const WindowVertex* polygon, int count);

// Lowers edge_dist (image order, top row first, width * height floats initialised to 1)
// to the distance from each pixel centre in `clip` to the polygon's boundary segments.
void addEdgeDistances(const WindowVertex* polygon, int count, const PixelRect& clip, int width,
                      int height, float* edge_dist);

}  // namespace rc::ref
