// The reference renderer's internals, shared by the files that implement it (not an API:
// reference_renderer.h is). One Renderer draws one frame (or one sample of it, or one
// traced pixel); its member functions live in the file of their concern:
//   draw_loop.cpp             vertices, passes, clipping, culling, fan set-up
//   fragment_loop.cpp         the fragment loop: depth test, shading, colour writes, tracing
//   renderer_uncertainty.cpp  what each vertex, fan and fragment adds to the channels
//   abuffer.cpp               ref:abuffer's kept fragments and their resolve
//   multisample_render.cpp    one render per sample and the resolve
// and reference_renderer.cpp holds the entry points and their input checks.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "fixtures/scene_logic.h"
#include "reference/clipper.h"
#include "reference/interpolation.h"
#include "reference/line_raster.h"
#include "reference/rasterizer.h"
#include "reference/reference_renderer.h"
#include "reference/shading.h"
#include "reference/texture_lod.h"
#include "reference/uncertainty.h"
#include "reference/vertex_stage.h"
#include "reference/vertex_windows.h"
#include "reference/viewport.h"

namespace rc::ref {

// A per-vertex error bound interpolated over a fan triangle in screen space: GL interpolates
// window z with the triangle's screen-space barycentrics (non-negative, summing to 1 at a
// covered pixel), so a fragment's depth error is at most the same combination of its
// vertices' errors. Clamped to the vertices' range (snapping may cover a centre just
// outside the exact triangle); a degenerate or non-finite setup gives the largest.
struct ReachPlane {
  double x0 = 0.0;
  double y0 = 0.0;
  double at0 = 0.0;
  double ddx = 0.0;
  double ddy = 0.0;
  double lo = 0.0;
  double hi = 0.0;

  void setup(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c, double ra,
             double rb, double rc) {
    x0 = a.x;
    y0 = a.y;
    at0 = ra;
    lo = std::min({ra, rb, rc});
    hi = std::max({ra, rb, rc});
    ddx = ddy = 0.0;
    const double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    const double gx = ((rb - ra) * (c.y - a.y) - (rc - ra) * (b.y - a.y)) / det;
    const double gy = ((b.x - a.x) * (rc - ra) - (c.x - a.x) * (rb - ra)) / det;
    if (det != 0.0 && std::isfinite(gx) && std::isfinite(gy)) {
      ddx = gx;
      ddy = gy;
    } else {
      at0 = lo = hi;
    }
  }
  float at(double x, double y) const {
    const double r = at0 + ddx * (x - x0) + ddy * (y - y0);
    return static_cast<float>(std::clamp(r, lo, hi));
  }
  // Adds e >= 0 steps everywhere (the plane set-up's error: planeSetupError() is never NaN;
  // its +inf stays +inf).
  void widen(double e) {
    at0 += e;
    lo += e;
    hi += e;
  }
};

// What the fragment loop needs about the original triangle being drawn.
// One object serves every triangle of a frame (Renderer::context_): drawWindowed() resets prim,
// pass and the flags read before they are set (constant, depth_slope, texel_choice,
// thin, short_normals);
// prepareTriangle() writes what its shading mode reads (material to v, gouraud, flat, the
// constant colour, centroid and face normal where lit or traced), the per-fan set-up the
// uncertainty fields. The initial values only matter for the first triangle.
struct TriangleContext {
  const PrimitiveRef* prim = nullptr;
  const DrawPass* pass = nullptr;
  const Material* material = nullptr;
  const PreparedShading* shading = nullptr;
  const Texture* texture = nullptr;
  // Level-of-detail sampling (Renderer::lod_): the material's mip chain, level 0 first.
  const std::vector<const Texture*>* chain = nullptr;
  const TransformedVertex* v[3] = {nullptr, nullptr, nullptr};
  const LitColor* gouraud[3] = {nullptr, nullptr, nullptr};  // per original vertex
  glm::dvec3 centroid{0.0};     // flat: world-space centroid of the original triangle
  glm::dvec3 face_normal{0.0};  // flat: normalize(cross(p1 - p0, p2 - p0))
  LitColor flat;
  bool constant = false;  // flat, untextured, not blended: one stored colour
  float constant_stored[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  // Of the fan triangle being drawn (uncertainty channels only):
  float depth_slope = 0.0f;    // |grad z| in depth-format steps per px
  ReachPlane depth_reach;      // steps: its vertices' float32 window-depth reach, interpolated,
                               // plus the float32 set-up of its depth plane (planeSetupError())
  bool texel_choice = false;   // textured: record the texel channels
  bool thin = false;           // thinner than kThinAltitudePx: records shade_reach
  bool short_normals = false;  // Phong, its normal can be short: records normal_reach
  double n_max = 0.0;          // short_normals: largest |n / w| over the fan's vertices
  double n_len_max = 0.0;      // short_normals: largest |N_k| of the triangle
  // Gouraud (uncertainty channels): per colour channel sum_k A_k grad N_k of AD and S, and
  // grad D (FragmentInterpolator::numeratorGradient()), for gouraudReach().
  glm::dvec2 ad_grad[3] = {};
  glm::dvec2 sp_grad[3] = {};
  glm::dvec2 den_grad{0.0};
  glm::dvec2 uq_max{0.0};         // largest |u / w|, |v / w| over its three vertices
  glm::dvec4 texture_range{0.0};  // linear filtering: textureRange() of its texture
  // The general fragment operations (Renderer::general_ops_), of the fan triangle:
  bool front_facing = true;     // the stencil face it uses
  double offset = 0.0;          // polygon offset, window-z units
  float offset_steps = 0.0f;    // |units| x r in depth-format steps (offset_steps channel)
  std::uint64_t plane_key = 0;  // its depth plane (compared() `invariant`), never 0
  // Lines and points (line_loop.cpp): the level of detail of the sample being shaded (NaN:
  // none, the fan's interpolator decides), and what explain records of the fragment.
  double line_lambda = std::numeric_limits<double>::quiet_NaN();
  LineTrace line_trace;
};

// What generalFragment() needs of a draw that does not change from fragment to fragment.
struct GeneralSetup {
  const StencilFace* face = nullptr;  // the stencil face the fragments test (none: no test)
  double near = 0.0;                  // depth range: window z = near + scale * z
  double scale = 1.0;
  bool mapped = false;      // a depth range other than [0, 1]
  bool tested = false;      // a depth function other than ALWAYS and NEVER
  float alpha = 0.0f;       // what the channels weigh the old colour by (1 - alpha)
  bool composited = false;  // blended or masked: the old colour shows through
};

// How close the pixel centre (cx, cy) comes to the other decision of GL's rule for the
// segment a -> b of rounded width w (px, measured in the minor direction: | |offset| - w/2 |),
// 0 in the columns (rows) within a pixel of an end, where GL leaves the fragment to the
// driver (and `end_reach` px more: how far float32 may move an end, a clipped one far), and
// for a width of k + 1/2 (either width) between the two bands. The reach of the vertices is
// not subtracted.
inline double segmentMargin(const WindowVertex& a, const WindowVertex& b, double w, bool half,
                            double cx, double cy, double end_reach = 0.0) {
  const bool x_major = std::fabs(b.x - a.x) >= std::fabs(b.y - a.y);
  const double ma = x_major ? a.x : a.y;
  const double mb = x_major ? b.x : b.y;
  const double na = x_major ? a.y : a.x;
  const double nb = x_major ? b.y : b.x;
  const double mc = x_major ? cx : cy;
  const double nc = x_major ? cy : cx;
  const double lo = std::min(ma, mb);
  const double hi = std::max(ma, mb);
  const double slope = mb != ma ? (nb - na) / (mb - ma) : 0.0;
  const double off = std::fabs(nc - (na + (std::clamp(mc, lo, hi) - ma) * slope));
  const bool end = std::fabs(mc - ma) < 1.0 + end_reach || std::fabs(mc - mb) < 1.0 + end_reach ||
                   mc <= lo || mc >= hi;
  if (end) return 0.0;
  if (!half) return std::fabs(off - w / 2);
  // Either width, w or w - 1: the rows between are open, the rest decided by the nearer.
  if (off >= (w - 1) / 2 && off < w / 2) return 0.0;
  return std::min(std::fabs(off - w / 2), std::fabs(off - (w - 1) / 2));
}
// For a point of side `size` at c: the distance to the square's border, inside or out.
inline double pointMargin(const WindowVertex& c, double size, double cx, double cy) {
  const double dx = std::fabs(cx - c.x) - size / 2.0;
  const double dy = std::fabs(cy - c.y) - size / 2.0;
  return dx <= 0.0 && dy <= 0.0 ? std::min(-dx, -dy) : std::max(dx, dy);
}

// What a drawn fragment adds to the texel channels (frame.h): nothing unless textured.
// And, despite the name, what it adds to shade_reach (interpolated colours).
struct TexelNote {
  float dist = 1.0f;    // px
  float alt = 0.0f;     // 8-bit units, weighted as the fragment's colour is in the pixel
  float gain = 0.0f;    // units per texel unit, weighted alike
  float reach = 0.0f;   // linear filtering: texels (s + t) the sample may move
  float shade = 0.0f;   // shade_reach: 8-bit units per px of vertex movement, weighted alike
  float normal = 0.0f;  // normal_reach: 8-bit units, weighted alike
};

// A blended fragment the A-buffer keeps (ReferenceOptions::abuffer) until its pixel's list
// is sorted and blended.
struct KeptFragment {
  std::uint32_t index = 0;  // pixel, framebuffer order
  std::uint32_t seq = 0;    // position of its triangle in the blending pass
  std::uint32_t id = 0;     // primitive id
  float slope = 0.0f;       // depth gradient, steps/px (uncertainty channels)
  double z = 0.0;           // clamped window depth: the sort key
  glm::dvec4 color{0.0};    // its colour and alpha, before blending
  float alpha = 0.0f;       // clamped opacity (uncertainty channels)
  TexelNote note;
};

// What the A-buffer's resolve found, per frame (or summed over the samples of a
// multisampled render, pixels counted once however many of their samples show it).
struct ABufferTally {
  static constexpr std::uint8_t kBlended = 1;   // the pixel holds blended fragments
  static constexpr std::uint8_t kUnsorted = 2;  // ... and the draw order is not depth order
  struct PairPixel {
    std::uint32_t near = 0;   // nearer, but drawn first
    std::uint32_t far = 0;    // farther, but drawn after it
    std::uint32_t index = 0;  // pixel, framebuffer order
    // Ordered by pair, then pixel (written out: clang-tidy misreads a defaulted <=>).
    bool operator<(const PairPixel& o) const {
      return std::tie(near, far, index) < std::tie(o.near, o.far, o.index);
    }
    bool operator==(const PairPixel& o) const {
      return near == o.near && far == o.far && index == o.index;
    }
  };
  std::vector<std::uint8_t> pixel_flags;  // per pixel
  std::vector<PairPixel> pair_pixels;     // each (pair, pixel) once
  std::uint64_t kept_fragments = 0;
};

// One sample of a multisampled render: every pixel's coverage and depth are decided at
// its centre + offset (px) instead of its centre. The snapped vertices move by the
// offset rounded to the subpixel grid (exact for the standard patterns at >= 4 bits:
// they are multiples of 1/16), as a rasterizer that snaps once and evaluates its edge
// functions at the sample does; the depth plane and edge_dist use the exact offset.
struct SampleShift {
  bool active = false;
  glm::dvec2 offset{0.0};  // sample position - (0.5, 0.5), px
  std::int64_t units_x = 0;
  std::int64_t units_y = 0;
};

class Renderer {
 public:
  // Renders into a framebuffer covering `clip` (GL window coordinates): the whole image,
  // or one pixel when trace is non-null.
  Renderer(const Scene& scene, const ReferenceOptions& options, const PixelRect& clip,
           std::vector<FragmentTrace>* trace, const SampleShift& shift = {},
           std::vector<SortedFragment>* sorted = nullptr);

  Frame run();
  // ref:abuffer, after run(): what the resolve found (renderMultisample() joins them).
  ABufferTally& abufferTally() { return abuffer_; }

 private:
  void transformVertices();
  void drawTriangle(const PrimitiveRef& prim, const DrawPass& pass);
  void prefetchRows(const PrimitiveRef& prim);
  void drawPolygon(const PrimitiveRef& prim, const DrawPass& pass, const ClipVertex* poly,
                   int count, bool clipped);
  bool windowVertexSetup(const ClipVertex& c, WindowVertex& wv, FixedVertex& fv, double& reach,
                         double& depth_reach) const;
  void vertexReach(const ClipVertex& c, double& reach, double& depth_reach) const;
  WindowSetup windowSetup() const;
  // Window set-up (and the reaches, with the channels) of vertices [begin, end) of an object,
  // from their records (records[0] is vertex begin's).
  void setUpWindows(std::size_t object, const WindowSetup& setup, std::size_t begin,
                    std::size_t end, const TransformedVertex* records);
  void drawWindowed(const PrimitiveRef& prim, const DrawPass& pass, const WindowVertex* wv,
                    const FixedVertex* fv, const double* reach, const double* depth_reach,
                    int count, bool clipped);
  void prepareTriangle(TriangleContext& t) const;
  __attribute__((noinline)) void addSampleEdgeDistances(const WindowVertex* wv, int count,
                                                        const double* reach);
  void shadeFan(const TriangleContext& t, const TriangleCoverage& coverage,
                const FragmentInterpolator& interp);
  template <DepthFormat kFormat, bool kGaps, bool kBarycentrics, class Shade>
  [[gnu::always_inline]] inline void fillSpans(const TriangleContext& t,
                                               const TriangleCoverage& coverage,
                                               const FragmentInterpolator& interp, Shade&& shade);
  template <DepthFormat kFormat>
  void shadeFanFormat(const TriangleContext& t, const TriangleCoverage& coverage,
                      const FragmentInterpolator& interp);
  // The per-fan inputs of the uncertainty channels (renderer_uncertainty.cpp): the fan
  // triangle wv[0], wv[i], wv[i + 1] of a polygon, `clipped` when it was cut.
  void setUpFanChannels(TriangleContext& t, const FragmentInterpolator& interp,
                        const WindowVertex* wv, const double* depth_reach, int i, bool clipped);
  // traceSpans() for the scene's shading mode.
  void traceFan(const TriangleContext& t, const TriangleCoverage& coverage,
                const FragmentInterpolator& interp);
  template <Shading kShading>
  void traceSpans(const TriangleContext& t, const TriangleCoverage& coverage,
                  const FragmentInterpolator& interp);
  // The texel note needs the interpolator at the fragment (interp, row, dx); without
  // `note` they are not read.
  template <Shading kShading>
  glm::dvec4 fragmentColor(const TriangleContext& t, const glm::dvec3& b, ShadingTerms* terms,
                           TexelNote* note = nullptr, const FragmentInterpolator* interp = nullptr,
                           const FragmentInterpolator::Row* row = nullptr, double dx = 0.0) const;
  float gouraudReach(const TriangleContext& t, const glm::dvec3& b, const LitColor& lit,
                     const glm::dvec3& tex, const FragmentInterpolator& interp,
                     const FragmentInterpolator::Row& row, double dx) const;
  float normalReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& p,
                    const FragmentInterpolator& interp, const FragmentInterpolator::Row& row,
                    double dx) const;
  // normal_reach of a shadowed Phong fragment: how far the lookups of its shadowed lights
  // may legally go (reference/shadow.h shadowRange()) times each light's unshadowed terms.
  float shadowReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& tex,
                    const FragmentInterpolator* interp, const FragmentInterpolator::Row* row,
                    double dx) const;
  float phongReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& tex,
                   const LitColor& lit, const FragmentInterpolator& interp,
                   const FragmentInterpolator::Row& row, double dx) const;
  TexelNote texelNote(const TriangleContext& t, const glm::dvec2& uv, const glm::dvec3& b,
                      const glm::dvec3& ambient_diffuse, const FragmentInterpolator& interp,
                      const FragmentInterpolator::Row& row, double dx) const;
  void traceTerms(const TriangleContext& t, const glm::dvec3& b, ShadingTerms& terms) const;
  // Level-of-detail sampling: the texture coordinate's derivatives (level-0 texels per px)
  // at the fragment, and the sample.
  void uvDerivatives(const TriangleContext& t, const FragmentInterpolator& interp,
                     const FragmentInterpolator::Row& row, double dx, const glm::dvec3& b,
                     glm::dvec2& d_dx, glm::dvec2& d_dy) const;
  glm::dvec4 lodTexel(const TriangleContext& t, const glm::dvec2& uv, const glm::dvec3& b,
                      const FragmentInterpolator& interp, const FragmentInterpolator::Row& row,
                      double dx, ShadingTerms* terms = nullptr) const;
  // The lambda interval a conforming driver may use at the fragment (renderer_uncertainty.cpp).
  std::pair<double, double> lodInterval(const TriangleContext& t,
                                        const FragmentInterpolator& interp,
                                        const FragmentInterpolator::Row& row, double dx) const;
  // The texel note of a level-of-detail fragment (renderer_uncertainty.cpp).
  TexelNote lodNote(const TriangleContext& t, const glm::dvec2& uv,
                    const glm::dvec3& ambient_diffuse, const FragmentInterpolator& interp,
                    const FragmentInterpolator::Row& row, double dx, double reach_s,
                    double reach_t) const;
  void writeColor(std::size_t index, const glm::dvec4& src, bool blend);
  // The general fragment operations (fragment_loop.cpp): scissor, stencil, depth (with
  // range and offset), blending, colour mask, in GL's order, every fragment through
  // fragmentColor(); traced when trace_ is set.
  template <Shading kShading>
  void fillSpansGeneral(const TriangleContext& t, const TriangleCoverage& coverage,
                        const FragmentInterpolator& interp);
  void shadeFanGeneral(const TriangleContext& t, const TriangleCoverage& coverage,
                       const FragmentInterpolator& interp);
  GeneralSetup generalSetup(const TriangleContext& t) const;
  // `extra_note()`: the fragment's own texel and colour notes (lines' slack), asked for only
  // when the fragment writes its colour.
  template <Shading kShading, class Bary, class Extra>
  void generalFragment(const TriangleContext& t, const GeneralSetup& g, int px, int py,
                       std::size_t index, double z_window, float reach, Bary&& bary,
                       const FragmentInterpolator* interp, const FragmentInterpolator::Row* row,
                       double dx, Extra&& extra_note);
  // Lines and points (line_loop.cpp): a line or point primitive of `pass`; the edges or
  // vertices of a triangle's (clipped) polygon in polygon mode line or point; one segment
  // or point in clip space (barycentrics w.r.t. the primitive's original vertices in
  // context_.v), rasterized and shaded.
  void drawLineOrPoint(const PrimitiveRef& prim, const DrawPass& pass);
  void drawPolygonOutline(const WindowVertex* wv, const FixedVertex* fv, const double* reach,
                          const double* depth_reach, int count);
  void drawSegment(const ClipVertex& a, const ClipVertex& b, bool polygon_edge);
  void drawSegmentWindowed(const WindowVertex& a, const WindowVertex& b, const FixedVertex& fa,
                           const FixedVertex& fb, double reach, double depth_reach,
                           bool polygon_edge);
  void drawPointWindowed(const WindowVertex& c, const FixedVertex& fc, double reach,
                         double depth_reach, bool polygon_vertex);
  void markAmbiguous(const WindowVertex& a, const WindowVertex& b, double radius);
  // The pixels GL leaves to the driver near the segment: its end columns, and those within
  // a 16th of a pixel of the rule's other decision (line_loop.cpp).
  std::vector<LinePixel> endCandidates(const WindowVertex& a, const WindowVertex& b, double w,
                                       bool half, double end_reach) const;
  std::vector<LinePixel> pointCandidates(const WindowVertex& c, double size) const;
  // The fragments of a segment (or point, a == b, segment false) of rasterized `size`
  // (fragment_loop.cpp): shadeLineFragments() for the scene's shading mode.
  void shadeLine(const std::vector<LinePixel>& pixels, const WindowVertex& a, const WindowVertex& b,
                 bool segment, double size, double depth_reach, bool polygon_edge);
  template <Shading kShading>
  void shadeLineFragments(const std::vector<LinePixel>& pixels, const WindowVertex& a,
                          const WindowVertex& b, bool segment, double size, double depth_reach,
                          bool polygon_edge);
  // The framebuffer index of pixel (px, py) of clip_ (GL window coordinates; rows stored
  // top down).
  std::size_t frameIndex(int px, int py) const {
    return static_cast<std::size_t>(clip_.y1 - 1 - py) * static_cast<std::size_t>(fb_width_) +
           static_cast<std::size_t>(px - clip_.x0);
  }
  // edge_dist at `index` lowered to max(0, d) (the channel keeps the least over all edges).
  void lowerEdgeDist(std::size_t index, double d) {
    float& e = frame_.edge_dist[index];
    e = std::min(e, static_cast<float>(std::max(0.0, d)));
  }
  void prepareLine(TriangleContext& t, const std::uint32_t* vertices, int count) const;
  // Per fan triangle: facing, polygon offset, the depth plane's key and what range and
  // offset add to its depth reach (draw_loop.cpp).
  void setUpGeneralFan(TriangleContext& t, const FragmentInterpolator& interp,
                       const WindowVertex& a, const WindowVertex& b, const WindowVertex& c,
                       bool front_facing);
  glm::dvec4 storedColor(std::size_t index) const;
  void resolveABuffer();

  const Scene& scene_;
  const ReferenceOptions& options_;
  const PixelRect clip_;
  const int fb_width_;
  const int fb_height_;
  std::vector<FragmentTrace>* trace_;
  std::vector<SortedFragment>* sorted_;  // abufferPixel(): the traced pixel's sorted list
  bool defer_blends_;                    // A-buffer: blends go to kept_ until resolved
  const bool uncertainty_;
  const DepthFormat depth_format_;
  const ColorFormat color_format_;
  const double snap_scale_;   // 2^subpixel_bits
  const double depth_steps_;  // depth-format steps per unit of window z
  const CameraTransform camera_;
  const Lighting lighting_;
  const ClipVolume volume_;
  std::vector<PreparedShading> shading_;            // per material
  std::vector<std::array<float, 4>> unlit_stored_;  // per material (prepareTriangle())
  TriangleContext context_;  // the triangle being drawn (drawWindowed(): reused, not rebuilt)

  std::vector<std::vector<TransformedVertex>>& vertices_;  // per object, scratch
  std::vector<std::vector<LitColor>>& gouraud_;            // per object, Gouraud only, scratch
  Frame frame_;                        // colour, id, edge_dist over the clip rectangle
  std::vector<std::uint32_t>& depth_;  // depth keys (fragment_ops.h), scratch
  UncertaintyTracker& gaps_;           // scratch
  EdgeDistanceBatch& edges_;           // scratch
  std::vector<std::vector<VertexWindow>>& windows_;  // per object, per vertex, scratch
  std::vector<TransformedVertex>& piece_;            // transformVertices(), scratch
  const SampleShift shift_;                          // multisampling: the sample drawn
  // Level-of-detail sampling (fixtures/scene.h lodSampling()): each material's mip chain.
  const bool lod_;
  const LodState lod_state_;
  std::vector<std::vector<std::shared_ptr<const Texture>>> chain_storage_;
  std::vector<std::vector<const Texture*>> chains_;
  // prefetchRows(): the first vertex of the last triangle it saw.
  double prefetch_x_ = -1e9;
  double prefetch_y_ = -1e9;
  std::uint64_t triangles_drawn_ = 0;  // fan triangles that reached the fragment loop
  std::uint64_t fragments_ = 0;        // covered pixel centres (depth tested or not)
  std::vector<KeptFragment> kept_;     // A-buffer: blended fragments, in draw order
  // Some pass is DrawPass::extended(): every pass goes through fillSpansGeneral() and the
  // tracker counts comparisons conservatively (UncertaintyTracker::compared()).
  bool general_ops_ = false;
  std::vector<std::uint8_t> stencil_;      // with a stencil format
  std::vector<std::uint64_t> plane_keys_;  // general_ops_: the plane that stored each depth
  std::uint32_t blend_seq_ = 0;            // triangles of blending passes drawn so far
  ABufferTally abuffer_;                   // A-buffer: what the resolve found
  // textureRange() of each texture met so far (linear filtering with uncertainty).
  std::vector<std::pair<const Texture*, glm::dvec4>> texture_ranges_;
  const glm::dvec4& textureRangeOf(const Texture* texture);
  // drawPolygonOutline(): the pixels (framebuffer indices, sorted) two of the polygon's
  // edges or vertices produce, whose last fragment GL leaves to the driver.
  std::vector<std::size_t> outline_shared_;
  // ... and, from a dry run of its fragments there (outline_dry_), their window depths and
  // colours, merged per pixel (sorted by index).
  struct OutlineSpread {
    std::size_t index = 0;
    double z_lo = 0.0;
    double z_hi = 0.0;
    glm::dvec3 c_lo{0.0};
    glm::dvec3 c_hi{0.0};
  };
  std::vector<OutlineSpread> outline_spread_;
  bool outline_dry_ = false;
};

// How far a float32 implementation may put the vertex beyond snapping (its clip
// coordinates' error through the divide and the viewport): its edges' reach, and the same
// error in window depth, which the driver interpolates between the vertices (a convex
// combination: the largest vertex's bounds it).
inline void Renderer::vertexReach(const ClipVertex& c, double& reach, double& depth_reach) const {
  reach = windowErrorPx(c, scene_.width, scene_.height);
  if (!(reach < kMaxVertexReachPx)) reach = kMaxVertexReachPx;  // NaN too
  const double dz = windowDepthError(c) * depth_steps_;
  depth_reach = std::isnan(dz) ? std::numeric_limits<double>::infinity() : dz;
}

// frame.json "abuffer" from a tally over the framebuffer rectangle `clip` of an image
// `image_height` rows high (abuffer.cpp).
nlohmann::json abufferMeta(ABufferTally& tally, const PixelRect& clip, int image_height);

// A scene with more than one sample (multisample_render.cpp); the scene and options are
// already checked.
Frame renderMultisample(const Scene& scene, const ReferenceOptions& options);

}  // namespace rc::ref
