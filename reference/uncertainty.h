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
//     UncertaintyTracker computes it in draw order, exactly (see there for why it is exact).
//     Not counted: tests against the clear depth (clear_gap below), and passes without a
//     depth test (painter's, depth_test false: ALWAYS), where the shared far-to-near sort
//     or the file order, identical in both renderers, decides the winner: no depth error
//     can change it, so a pixel drawn last by such a pass is +inf. In a single z-buffer
//     pass this is the gap between the winner and the nearest other fragment (DESIGN.md's
//     wording).
//   clear_gap: how close the pixel came to the other side of primitive-or-background: a
//     fragment within a step of the clear depth, near the far plane, may legally pass or
//     fail its test against it (UncertaintyTracker says which fragments count).
// It does not decide coverage or visibility.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "reference/fragment_ops.h"
#include "reference/prefetch.h"
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
// The same stream gives the other per-fragment channels (frame.h UncertaintyChannel):
//  - depth_slope: the depth gradient (steps/px) of the fragment that stored the depth;
//  - gap_slope: the steeper fragment of each comparison depth_gap counts, the largest
//    over them (reset with the gap when a passing fragment decides the id anew);
//  - clear_gap / clear_slope (finish()): whether the pixel could legally be background
//    where the reference drew something, or the reverse. Every tested fragment would have
//    to fail (for background) or one to pass (for a primitive) against the clear depth, so
//    a drawn pixel gets the LARGEST |z - clear| over its tested fragments, a background
//    pixel the smallest; +inf when a fragment was drawn without a test, or none was tested.
//    clear_slope: the steepest tested fragment;
//  - blend_gap / blend_slope: every test of a blended fragment against the stored depth
//    changes the pixel's colour when it flips, whether or not it decides the id; so do the
//    comparisons that decided the opaque fragment the first blend goes over (depth_gap and
//    clear_gap as they stand then): the smallest such gap, and the steepest fragment;
//  - depth_reach: the largest float32 reach (steps) of every fragment the pixel saw, drawn
//    or not: it bounds the stored depth's error and both sides of every comparison above;
//  - blend_count, texel_dist, texel_alt, texel_gain, texel_reach, shade_reach,
//    normal_reach: composited
//    like the colour itself (colourWritten()): an opaque write starts them afresh, a blended
//    one adds its own, weighted by alpha (texel_reach: the largest).
//
// Storage: the window depth of the fragment that stored each pixel's depth (a double: the
// gap must be exact), and the gaps already in steps, as the floats the frame keeps:
// x -> float(x * steps) never decreases, so the minimum of the converted gaps is the
// converted minimum.
class UncertaintyTracker {
 public:
  // Starts a frame whose uncertainty channels hold their initial values; they receive the
  // results as fragments arrive. `clear_z`: the clear depth, clamped to [0, 1].
  void reset(Frame& frame, DepthFormat format, double clear_z) {
    const std::size_t n = frame.pixelCount();
    stored_z_.assign(n, kInf);
    clear_near_.assign(n, kInfF);
    clear_far_.assign(n, -1.0f);  // < 0: no tested fragment yet
    clear_z_ = clear_z;
    steps_ = depthStepsPerUnit(format);
    gap_ = frame.depth_gap.data();
    gap_slope_ = frame.gap_slope.data();
    depth_slope_ = frame.depth_slope.data();
    blend_gap_ = frame.blend_gap.data();
    blend_slope_ = frame.blend_slope.data();
    blend_count_ = frame.blend_count.data();
    texel_dist_ = frame.texel_dist.data();
    texel_alt_ = frame.texel_alt.data();
    clear_slope_ = frame.clear_slope.data();
    texel_gain_ = frame.texel_gain.data();
    depth_reach_ = frame.depth_reach.data();
    texel_reach_ = frame.texel_reach.data();
    shade_reach_ = frame.shade_reach.data();
    normal_reach_ = frame.normal_reach.data();
    offset_steps_ = frame.offset_steps.data();
    shade_active_ = false;
    normal_active_ = false;
    texel_active_ = false;
    blend_active_ = false;
  }

  // Fragment at clamped window depth z, on a plane of depth gradient `slope` (steps/px)
  // whose vertices' window depth a float32 transform may move by `reach` (steps), passed
  // the test (tested: LESS; else ALWAYS) and, when `writes`, stored its depth.
  // `blended`: drawn in a blending pass.
  void passed(std::size_t index, double z, float slope, float reach, bool tested, bool writes,
              bool blended) {
    if (blended && blend_count_[index] == 0.0f) baseDecided(index);
    depth_reach_[index] = std::max(depth_reach_[index], reach);
    if (tested) {
      // +inf against the clear depth (|z - inf| = inf).
      const float g = toSteps(std::fabs(z - stored_z_[index]));
      gap_[index] = g;
      gap_slope_[index] = std::max(slope, depth_slope_[index]);
      clearTest(index, z, slope);
      if (blended) blendTest(index, z, slope);
    } else {
      gap_[index] = kInfF;
      gap_slope_[index] = 0.0f;
      clear_near_[index] = -kInfF;  // drawn whatever the depths: never background
    }
    if (writes) {
      stored_z_[index] = z;
      depth_slope_[index] = slope;
    }
  }
  // The general fragment operations (a scene with extended() passes, fixtures/scene_logic.h)
  // break the streaming rule's premises: other depth functions, no depth writes in opaque
  // passes, stencil values that depend on depth tests, blend functions. There every depth
  // comparison counts, whatever its outcome and order (a superset of those that decided,
  // so never a smaller gap than the exact rule would give):
  //  - compared(): a fragment tested against the stored depth (`tested`: the function
  //    compares at all, not NEVER or ALWAYS). Against the clear depth it goes to clear_gap
  //    (finishConservative() gives every pixel its smallest), else to depth_gap; blended,
  //    to blend_gap too with what decided the pixel so far. `invariant`: the stored depth
  //    came from the same depth plane (the same window vertices, range and offset): GL's
  //    invariance rules make that comparison come out the same in every implementation
  //    (equal-depth multipass), so it counts nowhere.
  //  - storedDepth(): the fragment wrote its depth.
  // `offset`: the fragment's |units| x r in steps (the offset_steps channel).
  void compared(std::size_t index, double z, float slope, float reach, float offset, bool tested,
                bool blended, bool invariant) {
    depth_reach_[index] = std::max(depth_reach_[index], reach);
    offset_steps_[index] = std::max(offset_steps_[index], offset);
    if (!tested || invariant) return;
    const bool against_clear = std::isinf(stored_z_[index]);
    const float g = toSteps(std::fabs(z - (against_clear ? clear_z_ : stored_z_[index])));
    if (against_clear) {
      clear_near_[index] = std::min(clear_near_[index], g);
      clear_far_[index] = std::max(clear_far_[index], g);
      clear_slope_[index] = std::max(clear_slope_[index], slope);
    } else {
      if (g < gap_[index]) gap_[index] = g;
      gap_slope_[index] = std::max({gap_slope_[index], slope, depth_slope_[index]});
    }
    if (blended) {
      float b = std::min(g, gap_[index]);
      if (clear_far_[index] >= 0.0f) b = std::min(b, clear_near_[index]);
      if (b < blend_gap_[index]) blend_gap_[index] = b;
      blend_slope_[index] = std::max({blend_slope_[index], slope, gap_slope_[index]});
    }
  }
  void storedDepth(std::size_t index, double z, float slope) {
    stored_z_[index] = z;
    depth_slope_[index] = slope;
  }
  // Ends a frame drawn with compared(): clear_gap is the closest comparison against the
  // clear depth at every pixel, drawn or not.
  void finishConservative(Frame& frame) {
    for (std::size_t i = 0; i < frame.pixelCount(); ++i)
      if (clear_far_[i] >= 0.0f) frame.clear_gap[i] = clear_near_[i];
  }

  // Fragment at clamped window depth z failed the LESS test.
  void failed(std::size_t index, double z, float slope, float reach, bool blended) {
    depth_reach_[index] = std::max(depth_reach_[index], reach);
    const float g = toSteps(std::fabs(z - stored_z_[index]));  // +inf against the clear depth
    clearTest(index, z, slope);
    if (blended) blendTest(index, z, slope);
    if (std::isinf(g)) return;
    if (g < gap_[index]) gap_[index] = g;
    gap_slope_[index] = std::max({gap_slope_[index], slope, depth_slope_[index]});
  }

  // A fragment's colour was written: over the old one when `blended` (with weight `alpha`),
  // else in its place. texel_dist / texel_alt are the fragment's own (texel_alt, texel_gain
  // and shade_reach already weighted by alpha when blended).
  void colourWritten(std::size_t index, bool blended, float alpha, float texel_dist,
                     float texel_alt, float texel_gain, float texel_reach, float shade_reach,
                     float normal_reach) {
    if (!texel_active_ && !initialTexel(texel_dist, texel_alt, texel_gain, texel_reach))
      texel_active_ = true;
    if (!blended) {
      if (blend_active_) blend_count_[index] = 0.0f;
      if (texel_active_) {
        texel_dist_[index] = texel_dist;
        texel_alt_[index] = texel_alt;
        texel_gain_[index] = texel_gain;
        texel_reach_[index] = texel_reach;
      }
      if (kept(shade_active_, shade_reach)) shade_reach_[index] = shade_reach;
      if (kept(normal_active_, normal_reach)) normal_reach_[index] = normal_reach;
      return;
    }
    if (kept(normal_active_, normal_reach))
      normal_reach_[index] = (1.0f - alpha) * normal_reach_[index] + normal_reach;
    if (kept(shade_active_, shade_reach))
      shade_reach_[index] = (1.0f - alpha) * shade_reach_[index] + shade_reach;
    blend_active_ = true;
    blend_count_[index] += 1.0f;
    if (texel_active_) {
      texel_reach_[index] = std::max(texel_reach_[index], texel_reach);
      texel_dist_[index] = std::min(texel_dist_[index], texel_dist);
      texel_alt_[index] = (1.0f - alpha) * texel_alt_[index] + texel_alt;
      texel_gain_[index] = (1.0f - alpha) * texel_gain_[index] + texel_gain;
    }
  }

  // The A-buffer's sorted list at a pixel (ReferenceOptions::abuffer): window depths z and
  // slopes of its n >= 1 blended fragments, far to near, after passed()/failed() saw them
  // in draw order. The nearest is the id: its test against the stored depth and its order
  // against the next nearest decide it (depth_gap, kept as the smaller of these and what
  // the stream gave); every neighbouring pair's order decides the colour, since another
  // implementation's depths may order them the other way within the gap (blend_gap).
  void sortedList(std::size_t index, const double* z, const float* slope, std::size_t n) {
    const std::size_t near = n - 1;
    if (!std::isinf(stored_z_[index])) {
      const float g = toSteps(std::fabs(z[near] - stored_z_[index]));
      if (g < gap_[index]) gap_[index] = g;
      gap_slope_[index] = std::max({gap_slope_[index], slope[near], depth_slope_[index]});
    }
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const float g = toSteps(z[k] - z[k + 1]);
      if (g < blend_gap_[index]) blend_gap_[index] = g;
      blend_slope_[index] = std::max({blend_slope_[index], slope[k], slope[k + 1]});
      if (k + 1 == near) {
        if (g < gap_[index]) gap_[index] = g;
        gap_slope_[index] = std::max({gap_slope_[index], slope[k], slope[near]});
      }
    }
  }

  // Prefetches pixels [begin, end) of the planes a fragment there will touch: those every
  // fragment touches, and those of the frame-wide groups once they are written
  // (Renderer::prefetchRows()).
  // What prefetch() always asks for, per pixel: stored_z_ and seven float planes.
  static constexpr std::size_t kPrefetchedBytesPerPixel = sizeof(double) + 7 * sizeof(float);
  void prefetch(std::size_t begin, std::size_t end) const {
    const auto span = [=](const auto* plane) { prefetchSpan(plane, begin, end); };
    span(stored_z_.data());
    span(clear_near_.data());
    span(clear_far_.data());
    span(clear_slope_);
    span(gap_);
    span(gap_slope_);
    span(depth_slope_);
    span(depth_reach_);
    if (blend_active_) {
      span(blend_count_);
      span(blend_gap_);
      span(blend_slope_);
    }
    if (texel_active_) {
      span(texel_dist_);
      span(texel_alt_);
      span(texel_gain_);
      span(texel_reach_);
    }
    if (shade_active_) span(shade_reach_);
    if (normal_active_) span(normal_reach_);
  }

  // Ends the frame: clear_gap from each pixel's final id (frame.id).
  void finish(Frame& frame) {
    for (std::size_t i = 0; i < frame.pixelCount(); ++i) {
      if (clear_near_[i] == -kInfF || clear_far_[i] < 0.0f) continue;  // stays +inf
      frame.clear_gap[i] = frame.id[i] != 0 ? clear_far_[i] : clear_near_[i];
    }
  }

  // The storage, for reuse between frames (reset() refills it).
  std::size_t capacity() const { return stored_z_.capacity(); }
  void release() {
    stored_z_ = {};
    clear_near_ = {};
    clear_far_ = {};
  }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr float kInfF = std::numeric_limits<float>::infinity();
  float toSteps(double gap) const { return static_cast<float>(gap * steps_); }
  void clearTest(std::size_t index, double z, float slope) {
    const float g = toSteps(std::fabs(z - clear_z_));
    if (clear_near_[index] != -kInfF) clear_near_[index] = std::min(clear_near_[index], g);
    clear_far_[index] = std::max(clear_far_[index], g);
    clear_slope_[index] = std::max(clear_slope_[index], slope);
  }
  // The first blend over the pixel's opaque colour: what decided that opaque fragment (or
  // the background) decides the blended colour too.
  void baseDecided(std::size_t index) {
    float g = gap_[index];
    float s = gap_slope_[index];
    if (!std::isinf(stored_z_[index])) {  // a drawn base might have been background
      g = std::min(g, clear_far_[index]);
      s = std::max(s, clear_slope_[index]);
    }
    if (g < blend_gap_[index]) blend_gap_[index] = g;
    blend_slope_[index] = std::max(blend_slope_[index], s);
  }
  // A blended fragment's test against the stored depth (the clear depth counts here: it
  // decides whether the fragment is blended at all).
  void blendTest(std::size_t index, double z, float slope) {
    const double s = std::isinf(stored_z_[index]) ? clear_z_ : stored_z_[index];
    const float g = toSteps(std::fabs(z - s));
    if (g < blend_gap_[index]) blend_gap_[index] = g;
    blend_slope_[index] = std::max({blend_slope_[index], slope, depth_slope_[index]});
  }

  // Window depth of the fragment that stored the pixel's depth; +inf while it holds the
  // clear depth (comparisons with it never count in depth_gap).
  std::vector<double> stored_z_;
  // |z - clear| (steps) over the pixel's tested fragments: smallest (-inf once a fragment
  // was drawn without a test) and largest (< 0 before the first).
  std::vector<float> clear_near_;
  std::vector<float> clear_far_;
  double clear_z_ = 1.0;
  double steps_ = 1.0;
  float* gap_ = nullptr;
  float* gap_slope_ = nullptr;
  float* depth_slope_ = nullptr;
  float* blend_gap_ = nullptr;
  float* blend_slope_ = nullptr;
  float* blend_count_ = nullptr;
  float* texel_dist_ = nullptr;
  float* texel_alt_ = nullptr;
  float* clear_slope_ = nullptr;
  float* texel_gain_ = nullptr;
  float* depth_reach_ = nullptr;
  float* texel_reach_ = nullptr;
  float* shade_reach_ = nullptr;
  float* normal_reach_ = nullptr;
  float* offset_steps_ = nullptr;
  // Whether a fragment has had a shade_reach (normal_reach) other than 0 this frame. Until
  // one has, every value of the plane is its initial 0 and every write would store 0 again:
  // they are skipped, so that frames without thin triangles (short normals), most, do not
  // write one more plane per fragment.
  bool shade_active_ = false;
  bool normal_active_ = false;
  static bool kept(bool& active, float value) {
    if (value != 0.0f) active = true;
    return active;
  }
  // The same for the four texel planes and blend_count, which every written fragment
  // touched (an untextured one storing their initial values, an opaque one blend_count 0):
  // until a fragment brings a texel value other than the initial ones (bit for bit: -0 is
  // stored as -0) the planes hold only initial values, and so would every write; until a
  // blended fragment has been written, every blend_count is 0. (A blended write of initial
  // texel values over initial ones leaves them too: min(1, 1), max(0, 0), (1 - a) 0 + 0 =
  // +0 for a in [0, 1].) In an untextured, opaque frame the five planes are not touched per
  // fragment at all (docs/performance.md, "Why the hot code looks the way it does").
  bool texel_active_ = false;
  bool blend_active_ = false;
  static bool sameBits(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
  }
  static bool initialTexel(float dist, float alt, float gain, float reach) {
    return sameBits(dist, 1.0f) && sameBits(alt, 0.0f) && sameBits(gain, 0.0f) &&
           sameBits(reach, 0.0f);
  }
};

// Twice the signed area (> 0 counter-clockwise) and the perimeter of a window polygon.
double polygonArea2(const WindowVertex* polygon, int count);
double polygonPerimeter(const WindowVertex* polygon, int count);

// A vertex whose float32 position is this uncertain (px) can be anywhere that matters:
// capping the reach keeps the edge-distance band (1 + reach) of one polygon bounded.
inline constexpr double kMaxVertexReachPx = 64.0;

// Moving each vertex by up to this many pixels (half a step at 3 subpixel bits: coarser
// than any driver measured, softpipe snaps to 1/16) is how much another implementation's
// snapping may disagree with ours.
inline constexpr double kSnapDisagreementPx = 1.0 / 16.0;

// Whether moving each vertex by d = kSnapDisagreementPx + extra_px (snapping, and the
// vertices' float32 error) could change the sign of the polygon's area:
// |2A| <= 2 * d * perimeter + 4 * d^2, since moving vertex i by d changes 2A by at most
// d * |v(i+1) - v(i-1)| <= d * (|e(i-1)| + |e(i)|).
bool cullCouldFlip(const WindowVertex* polygon, int count, double extra_px = 0.0);

// How far (window-z units) a float32 implementation's set-up of a triangle's depth plane
// may move the depth it interpolates at any point within 1 px (in x and in y) of the
// triangle, to first order in the float32 unit roundoff: docs/tolerances.md, "Plane
// set-up". GL implementations compute the plane from the window vertices as
// z = z_a + gx (x - x_a) + gy (y - y_a), the gradient from the edge vectors u = b - a and
// v = c - a over the cross product u x v; which vertex is `a` is theirs to choose, so the
// bound is the largest over the three choices. Small for ordinary triangles (about
// 13 u |z range|), large for slivers, where u x v cancels: a triangle 78 px long and 0.05 px
// wide seen edge-on put llvmpipe's depth 144 d24 steps from the plane (campaign s20261226).
// +inf when the unsnapped area is zero or anything is not finite.
double planeSetupError(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2);
// The same for the pieces an implementation that clips to the viewport's sides (GL's clip
// volume; a guard band is its option) may draw instead of the triangle: the triangle clipped
// to [0, width] x [0, height] in window space, fanned from each of its vertices in turn, the
// largest planeSetupError() of a piece that covers a pixel centre (within 0.01 px). 0 for a
// triangle inside the viewport. A side clip can leave a sliver piece along an edge whose set-up
// is far worse conditioned than the triangle's (docs/tolerances.md section 2, "Side clips").
double sideClipSetupError(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                          double width, double height);

// Lowers edge_dist (image order, top row first, width * height floats initialised to 1)
// to the distance from each pixel centre in `clip` to the polygon's boundary segments,
// less each segment's reach: how far a float32 implementation may put it beyond snapping
// (the larger of its end points' reach_px, windowErrorPx(); none when null), at least 0.
void addEdgeDistances(const WindowVertex* polygon, int count, const PixelRect& clip, int width,
                      int height, float* edge_dist, const double* reach_px = nullptr);

// addEdgeDistances() for many polygons, deferred and applied in row order. A visit of a
// pixel by a segment leaves min(cur, float(max(d, 0))) (when d < cur the stored float is
// <= cur, float conversion being monotone and cur a float; when d >= cur it is >= cur),
// and whether a pixel is visited does not depend on its value, so edge_dist is the minimum
// over all visits whatever the polygons' order: applying them sorted by their lowest row
// gives the same bits, while the band of rows being written stays in cache (polygons drawn
// in random places otherwise miss it on nearly every row).
class EdgeDistanceBatch {
 public:
  void clear() {
    segments_.clear();
    triangles_.clear();
  }
  // The polygon's vertex positions and per-vertex reach, as addEdgeDistances() takes them.
  void add(const WindowVertex* polygon, int count, const double* reach_px);
  // addEdgeDistances() of every added polygon into edge_dist, then clear().
  void apply(const PixelRect& clip, int width, int height, float* edge_dist);
  std::size_t capacity() const { return segments_.capacity() + triangles_.capacity(); }
  void release() {
    const bool wide = wide_lanes_;
    *this = {};
    wide_lanes_ = wide;
  }
  // Whether this processor runs the small-triangle pass eight centres at a time (AVX-512);
  // allowWideLanes(false) keeps this batch to four (the same bits: tests run both).
  static bool wideLanesAvailable();
  void allowWideLanes(bool allowed) { wide_lanes_ = allowed; }

 private:
  // One boundary segment with its reach (the larger of its end points'), kept whole so
  // that the sorted pass reads them in sequence.
  struct Segment {
    double ax;
    double ay;
    double bx;
    double by;
    double reach;
    std::int32_t key;  // its lower row, clamped to [0, 65536] (the sort key)
  };
  // A triangle at most kSmallTrianglePx across with narrow reaches, kept whole: its three
  // edges are applied in one pass over its box (addSmallTriangle() in uncertainty.cpp).
  struct SmallTriangle {
    double x[3];
    double y[3];
    double reach[3];   // of the edge from vertex k to vertex k + 1
    std::int32_t key;  // its lowest row, clamped to [0, 65536]
  };
  std::vector<Segment> segments_;
  std::vector<Segment> sorted_;
  std::vector<SmallTriangle> triangles_;
  std::vector<SmallTriangle> sorted_triangles_;
  std::vector<std::uint32_t> starts_;
  bool wide_lanes_ = true;
};

}  // namespace rc::ref
