// The uncertainty channels: what the reference knows about where another conforming
// rasterizer may legally differ from it.
//   edge_dist: per pixel, the distance in pixels from the pixel centre to the nearest
//     boundary edge SEGMENT (unsnapped window coordinates) of any rasterized polygon,
//     capped at 1. Polygons are the clipped triangles (their boundary, not the internal
//     fan diagonals), after culling, plus culled or zero-area ones whose cull decision a
//     snap of another implementation could flip (cullCouldFlip()). Computed in a band
//     around each edge, so the cost follows the perimeter, not the area.
//   depth_gap: per pixel, how close the depth comparisons that decided the final id came
//     to flipping. A comparison is one fragment f tested (LESS) against the depth stored
//     by an earlier fragment s; it DECIDED the final id when flipping its outcome alone
//     would change the final id. depth_gap = min |z_f - z_s| over those comparisons, in
//     steps of the depth format (d16/d24: * (2^b - 1); d32f: * 2^24), z the clamped,
//     unquantized window depth of each fragment; +inf when no comparison decided it.
//     DepthGapTracker computes it in draw order, exactly (see there for why it is exact).
//     Not counted: tests against the clear depth (they decide primitive vs background,
//     which the comparator never excuses by depth), and passes without a depth test
//     (painter's, depth_test false: ALWAYS), where the shared far-to-near sort or the file
//     order, identical in both renderers, decides the winner: no depth error can change it,
//     so a pixel drawn last by such a pass is +inf. In a single z-buffer pass this is the
//     gap between the winner and the nearest other fragment (DESIGN.md's wording).
// It does not decide coverage or visibility.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "fixtures/scene.h"
#include "reference/fragment_ops.h"
#include "reference/rasterizer.h"
#include "reference/viewport.h"

namespace rc::ref {

// Per-pixel state of the depth_gap rule above, fed every fragment in draw order with the
// outcome of its depth test. Why the streaming rule is exact:
//  - a fragment that passes becomes the final id so far, and no EARLIER comparison decides
//    the final id any more: with depth writes (a z-buffer pass) the new fragment is nearer
//    than everything stored before it, so it passes whatever an earlier flip would have
//    stored; without writes (the alpha pass, tested against the opaque depth) it is drawn
//    later than every earlier fragment and wins regardless of their outcomes. Its own
//    comparison does decide (failing, it would leave the previous id): gap = |z_f - z_s|;
//  - a fragment that fails is compared with the stored depth; passing instead, it would
//    become the final id unless a later fragment passes (which resets the gap anyway):
//    gap = min(gap, |z_f - z_s|);
//  - a fragment drawn without a test (ALWAYS) becomes the final id whatever the depths:
//    gap = +inf;
//  - comparisons against the clear depth are not counted (s is "clear").
// Flipping an opaque-pass comparison under a transparent winner can only change the final
// id through a transparent fragment whose depth lies between the two opaque candidates;
// that fragment's own comparison is then closer and is counted, so the minimum is the same.
//
// Storage: the window depth of the fragment that stored each pixel's depth (a double: the
// gap must be exact), and the running gap already in steps, as the float the frame keeps:
// x -> float(x * steps) never decreases, so the minimum of the converted gaps is the
// converted minimum.
class DepthGapTracker {
 public:
  // Starts a frame: `gap_steps` (pixels floats, the frame's depth_gap channel) must hold
  // +inf; it receives the result as fragments arrive.
  void reset(std::size_t pixels, DepthFormat format, float* gap_steps) {
    stored_z_.assign(pixels, kInf);
    steps_ = depthStepsPerUnit(format);
    gap_ = gap_steps;
  }

  // Fragment at clamped window depth z passed the test (tested: LESS; else ALWAYS) and,
  // when `writes`, stored its depth.
  void passed(std::size_t index, double z, bool tested, bool writes) {
    // +inf against the clear depth (|z - inf| = inf) and without a test.
    gap_[index] = tested ? toSteps(std::fabs(z - stored_z_[index])) : kInfF;
    if (writes) stored_z_[index] = z;
  }
  // Fragment at clamped window depth z failed the LESS test.
  void failed(std::size_t index, double z) {
    const float g = toSteps(std::fabs(z - stored_z_[index]));  // +inf against the clear depth
    if (g < gap_[index]) gap_[index] = g;
  }

  // The storage, for reuse between frames (reset() refills it).
  std::size_t capacity() const { return stored_z_.capacity(); }
  void release() { stored_z_ = {}; }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr float kInfF = std::numeric_limits<float>::infinity();
  float toSteps(double gap) const { return static_cast<float>(gap * steps_); }

  // Window depth of the fragment that stored the pixel's depth; +inf while it holds the
  // clear depth (comparisons with it never count).
  std::vector<double> stored_z_;
  double steps_ = 1.0;
  float* gap_ = nullptr;
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
