// The reference renderer: drives the stages in the draw order of fixtures/scene_logic.h
// drawPasses(). See reference_renderer.h and docs/reference.md.
#include "reference/reference_renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "fixtures/big_buffer.h"
#include "fixtures/errors.h"
#include "fixtures/multisample.h"
#include "fixtures/scene_geometry.h"
#include "fixtures/scene_logic.h"
#include "reference/clipper.h"
#include "reference/fragment_ops.h"
#include "reference/interpolation.h"
#include "reference/prefetch.h"
#include "reference/rasterizer.h"
#include "reference/shading.h"
#include "reference/shading_lanes.h"
#include "reference/texture_sampling.h"
#include "reference/uncertainty.h"
#include "reference/vertex_stage.h"
#include "reference/vertex_windows.h"
#include "reference/viewport.h"

namespace rc {
namespace {

using namespace rc::ref;

constexpr int kMaxImageSide = 16384;
constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 26;
// frame.json "abuffer.out_of_order" lists at most this many triangle pairs (most pixels
// first); "out_of_order_pairs" counts them all.
constexpr std::size_t kMaxReportedPairs = 64;

// ---- input validation -------------------------------------------------------------------

// The scene's own consistency is fixtures' validateForRendering(), shared with the GL
// backend; what is checked here is what only the reference limits: its options and the
// image size it allocates.
void validate(const Scene& scene, const ReferenceOptions& options) {
  validateForRendering(scene);
  const std::string label = sceneLabel(scene);
  auto fail = [&](const std::string& what) { throw InputError(label + ": " + what); };
  if (options.subpixel_bits < 0 || options.subpixel_bits > kMaxSubpixelBits)
    fail("reference subpixel bits " + std::to_string(options.subpixel_bits) + " out of range [0, " +
         std::to_string(kMaxSubpixelBits) + "]");
  if (scene.width > kMaxImageSide || scene.height > kMaxImageSide ||
      std::int64_t{scene.width} * scene.height > kMaxImagePixels)
    fail("image " + std::to_string(scene.width) + "x" + std::to_string(scene.height) +
         " outside what the reference renders (1..16384 a side, at most 2^26 pixels)");
}

// ---- the renderer -----------------------------------------------------------------------

// What the fragment loop needs about the original triangle being drawn.
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

// Gouraud and Phong fan triangles thinner than this (px, the smallest altitude of the
// unsnapped triangle) record shade_reach (gouraudReach(), phongReach()): their pixels may
// have no neighbour of the same primitive across the thin direction, which is where the
// neighbours' gradient fails (docs/tolerances.md (b)); in thicker ones it does not, and
// the channel's cost (more than the rest of a Gouraud fragment's uncertainty work) is not
// spent.
constexpr double kThinAltitudePx = 1.0;

// The smallest altitude (px) of the window triangle: twice its area over its longest edge
// (0 for a degenerate one; NaN where a coordinate is not finite).
inline double minAltitudePx(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
  const double area2 = std::fabs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
  const double longest =
      std::max({std::hypot(b.x - a.x, b.y - a.y), std::hypot(c.x - b.x, c.y - b.y),
                std::hypot(a.x - c.x, a.y - c.y)});
  return longest > 0.0 ? area2 / longest : 0.0;
}

// Whether the interpolated normal of a triangle with these vertex normals can be short
// against them (|n| < max_k |N_k| / 2 somewhere): a vertex normal under half the longest,
// or two at 60 degrees or more. Elsewhere normal_reach is below 1e-5 of the colour, far
// inside the relative term (docs/tolerances.md (a)), and is not computed. `longest`: the
// longest |N_k| (normalReach() needs it too).
inline bool canBeShort(const glm::dvec3& n0, const glm::dvec3& n1, const glm::dvec3& n2,
                       double& longest) {
  const double l[3] = {glm::length(n0), glm::length(n1), glm::length(n2)};
  longest = std::max({l[0], l[1], l[2]});
  if (!(std::min({l[0], l[1], l[2]}) >= 0.5 * longest)) return true;  // NaN too
  return glm::dot(n0, n1) < 0.5 * l[0] * l[1] || glm::dot(n1, n2) < 0.5 * l[1] * l[2] ||
         glm::dot(n2, n0) < 0.5 * l[2] * l[0];
}

// 16 ulps of float32: the error a driver's interpolated normal may carry, relative to the
// magnitudes its planes hold (as kTexelCoordinateReach for texture coordinates).
constexpr double kNormalReach = 0x1p-20;

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
};

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
nlohmann::json abufferMeta(ABufferTally& tally, const PixelRect& clip, int image_height);

// Working buffers that are not part of the Frame (depth keys and depth_gap state: 12 bytes
// a pixel; transformed vertices: 96 bytes each, Gouraud colours: 48), kept per thread
// between renders so that rendering many frames does not page-fault fresh memory each
// time; buffers over the kMaxKept* sizes are released after the frame. Contents never
// carry over: every render refills what it reads.
struct Scratch {
  std::vector<std::uint32_t> depth;
  UncertaintyTracker gaps;
  EdgeDistanceBatch edges;  // the polygons' edge_dist work, applied at the end of the frame
  std::vector<std::vector<TransformedVertex>> vertices;  // per object
  std::vector<std::vector<LitColor>> gouraud;            // per object, Gouraud only
  std::vector<std::vector<VertexWindow>> windows;        // per object, per vertex
  std::vector<TransformedVertex> piece;                  // transformVertices(): one piece's records
};
thread_local Scratch t_scratch;
constexpr std::size_t kMaxKeptScratchPixels = std::size_t{1} << 22;
constexpr std::size_t kMaxKeptScratchVertices = std::size_t{1} << 20;

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
           std::vector<SortedFragment>* sorted = nullptr)
      : scene_(scene),
        options_(options),
        clip_(clip),
        fb_width_(clip.x1 - clip.x0),
        fb_height_(clip.y1 - clip.y0),
        trace_(trace),
        sorted_(sorted),
        defer_blends_(options.abuffer),
        uncertainty_(options.uncertainty && trace == nullptr),
        depth_format_(scene.state.depth_format),
        color_format_(scene.state.color_format),
        snap_scale_(std::ldexp(1.0, options.subpixel_bits)),
        depth_steps_(depthStepsPerUnit(scene.state.depth_format)),
        camera_(cameraTransform(scene)),
        lighting_(sceneLighting(scene)),
        volume_(clipVolume(scene.width, scene.height, guardLimitPx(options.subpixel_bits))),
        vertices_(t_scratch.vertices),
        gouraud_(t_scratch.gouraud),
        depth_(t_scratch.depth),
        gaps_(t_scratch.gaps),
        edges_(t_scratch.edges),
        windows_(t_scratch.windows),
        piece_(t_scratch.piece),
        shift_(shift) {
    shading_.reserve(scene.materials.size());
    for (const Material& m : scene.materials) shading_.push_back(prepareShading(lighting_, m));
    // prepareTriangle()'s colour of an unlit, untextured, unblended flat triangle: one per
    // material (the same expressions, computed once instead of per triangle).
    unlit_stored_.resize(scene.materials.size());
    for (std::size_t m = 0; m < scene.materials.size(); ++m) {
      const glm::dvec4 c = finalColor(LitColor{shading_[m].ambient, glm::dvec3(0.0)},
                                      glm::dvec3(1.0), scene.materials[m].opacity);
      for (int k = 0; k < 4; ++k) unlit_stored_[m][k] = storeColor(c[k], color_format_);
    }
  }

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
  float phongReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& tex,
                   const LitColor& lit, const FragmentInterpolator& interp,
                   const FragmentInterpolator::Row& row, double dx) const;
  TexelNote texelNote(const TriangleContext& t, const glm::dvec2& uv, const glm::dvec3& b,
                      const glm::dvec3& ambient_diffuse, const FragmentInterpolator& interp,
                      const FragmentInterpolator::Row& row, double dx) const;
  void traceTerms(const TriangleContext& t, const glm::dvec3& b, ShadingTerms& terms) const;
  void writeColor(std::size_t index, const glm::dvec4& src, bool blend);
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
  // prefetchRows(): the first vertex of the last triangle it saw.
  double prefetch_x_ = -1e9;
  double prefetch_y_ = -1e9;
  std::uint64_t triangles_drawn_ = 0;  // fan triangles that reached the fragment loop
  std::uint64_t fragments_ = 0;        // covered pixel centres (depth tested or not)
  std::vector<KeptFragment> kept_;     // A-buffer: blended fragments, in draw order
  std::uint32_t blend_seq_ = 0;        // triangles of blending passes drawn so far
  ABufferTally abuffer_;               // A-buffer: what the resolve found
  // textureRange() of each texture met so far (linear filtering with uncertainty).
  std::vector<std::pair<const Texture*, glm::dvec4>> texture_ranges_;
  const glm::dvec4& textureRangeOf(const Texture* texture);
};

const glm::dvec4& Renderer::textureRangeOf(const Texture* texture) {
  for (const auto& [t, range] : texture_ranges_)
    if (t == texture) return range;
  texture_ranges_.emplace_back(texture, textureRange(*texture));
  return texture_ranges_.back().second;
}

void Renderer::transformVertices() {
  // Kept from the last frame (scratch): every vertex kept is rewritten below.
  vertices_.resize(scene_.objects.size());
  windows_.resize(scene_.objects.size());
  const Shading shading = scene_.state.shading;
  if (shading == Shading::Gouraud) gouraud_.resize(scene_.objects.size());
  const WindowSetup setup = windowSetup();
  for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
    const Object& obj = scene_.objects[o];
    if (obj.mesh.triangles.empty()) {
      vertices_[o].clear();
      windows_[o].clear();
      continue;
    }
    const std::size_t n = obj.mesh.positions.size();
    vertices_[o].resize(n);
    windows_[o].resize(n);
    if (shading == Shading::Gouraud) gouraud_[o].resize(n);
    // Flat shading lights the face normal: vertex normals would go unused (unless traced).
    const ObjectTransform transform(obj, camera_, shading != Shading::Flat || trace_ != nullptr,
                                    uncertainty_);
    const PreparedShading& prepared = shading_[obj.material];
    // Flat, unlit, untextured and not traced, nothing reads a vertex's record after its
    // window set-up (prepareTriangle() and the fragment loops read the windows) unless one
    // of its triangles is clipped (drawTriangle() reads the clip coordinates then). So while
    // every vertex so far is inside the clip volume, each piece's records go to one buffer
    // that stays in the cache instead of to the object's array: for a soup of small
    // triangles that array is 128 bytes a vertex of memory written for nothing. At the first
    // vertex outside, the pieces so far are transformed again into the array (the same
    // bits) and the rest are written there as before.
    bool records_unread = shading == Shading::Flat && trace_ == nullptr &&
                          scene_.materials[obj.material].texture == nullptr &&
                          prepared.lights.empty();
    // In pieces that stay in the cache from the transform to the window set-up (and
    // Gouraud's lighting): 512 x (128 + 72) bytes.
    constexpr std::size_t kPiece = 512;
    if (records_unread) piece_.resize(kPiece);
    for (std::size_t begin = 0; begin < n; begin += kPiece) {
      const std::size_t end = std::min(n, begin + kPiece);
      if (records_unread) {
        transform.applyInto(begin, end, piece_.data());
        setUpWindows(o, setup, begin, end, piece_.data());
        const VertexWindow* w = windows_[o].data();
        if (std::all_of(w + begin, w + end, [](const VertexWindow& v) {
              return (v.flags & VertexWindow::kInside) != 0;
            }))
          continue;
        // This piece's windows are set; its records and the earlier pieces' now go to the
        // array too, and the later pieces' straight there. (Flat: no lighting below.)
        records_unread = false;
        transform.apply(0, end, vertices_[o].data());
        continue;
      }
      transform.apply(begin, end, vertices_[o].data());
      setUpWindows(o, setup, begin, end, vertices_[o].data() + begin);
      if (shading != Shading::Gouraud) continue;
      // Gouraud lights each original vertex once: AD and S, interpolated per fragment.
      for (std::size_t i = begin; i < end; ++i)
        gouraud_[o][i] = shadePrepared(prepared, vertices_[o][i].world, vertices_[o][i].normal);
    }
  }
}

Frame Renderer::run() {
  const auto start = std::chrono::steady_clock::now();
  float clear_rgba[4];
  for (int c = 0; c < 4; ++c) clear_rgba[c] = storeColor(scene_.clear_color[c], color_format_);
  const std::uint32_t clear_key = depthKey(clampDepth(scene_.clear_depth), depth_format_);
  // The depth plane is written once, from the keys, when the frame is drawn.
  frame_.allocate(fb_width_, fb_height_, clear_rgba, std::nullopt, uncertainty_);
  depth_.assign(frame_.pixelCount(), clear_key);
  if (uncertainty_) gaps_.reset(frame_, depth_format_, clampDepth(scene_.clear_depth));
  edges_.clear();

  transformVertices();
  // Prefetch only where the planes the fragments touch can be out of the cache: colour,
  // depth key and id, and with the channels the tracker's.
  constexpr std::size_t kPlainBytes = 4 * sizeof(float) + 2 * sizeof(std::uint32_t);
  const std::size_t frame_bytes =
      frame_.pixelCount() *
      (kPlainBytes + (uncertainty_ ? UncertaintyTracker::kPrefetchedBytesPerPixel : 0));
  const bool prefetch = frame_bytes >= PrefetchBox::kMinFrameBytes;
  for (const DrawPass& pass : drawPasses(scene_, options_.force_painter)) {
    const std::vector<PrimitiveRef>& prims = pass.primitives;
    for (std::size_t j = 0; j < prims.size(); ++j) {
      if (prefetch && j + PrefetchBox::kAhead < prims.size())
        prefetchRows(prims[j + PrefetchBox::kAhead]);
      drawTriangle(prims[j], pass);
      if (pass.blend) ++blend_seq_;
    }
  }
  if (options_.abuffer) resolveABuffer();
  if (uncertainty_) {
    edges_.apply(clip_, fb_width_, fb_height_, frame_.edge_dist.data());
    gaps_.finish(frame_);
  }

  // Stored depth back to [0, 1].
  const std::uint32_t* keys = depth_.data();
  assignBigChunked(
      frame_.depth, frame_.pixelCount(),
      [keys, format = depth_format_](float* out, std::size_t begin, std::size_t count) {
        storedDepthPlane(keys + begin, count, format, out);
      });
  if (depth_.capacity() > kMaxKeptScratchPixels) depth_ = {};
  if (gaps_.capacity() > kMaxKeptScratchPixels) gaps_.release();
  if (edges_.capacity() > kMaxKeptScratchPixels) edges_.release();
  std::size_t kept_vertices = 0;
  for (const auto& v : vertices_) kept_vertices += v.capacity();
  if (kept_vertices > kMaxKeptScratchVertices) {
    vertices_ = {};
    gouraud_ = {};
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  frame_.meta = {{"renderer", "rastercheck reference"},
                 {"subpixel_bits", options_.subpixel_bits},
                 {"painter_forced", options_.force_painter},
                 {"triangles_rasterized", triangles_drawn_},
                 {"fragments", fragments_},
                 {"timing_ms", {{"render", ms}}}};
  if (options_.abuffer && !shift_.active)
    frame_.meta["abuffer"] = abufferMeta(abuffer_, clip_, scene_.height);
  return std::move(frame_);
}

void Renderer::prepareTriangle(TriangleContext& t) const {
  const Object& obj = scene_.objects[t.prim->object];
  const auto& tri = obj.mesh.triangles[t.prim->triangle];
  t.material = &scene_.materials[obj.material];
  t.shading = &shading_[obj.material];
  t.texture = t.material->texture.get();
  for (int k = 0; k < 3; ++k) {
    t.v[k] = &vertices_[t.prim->object][tri[k]];
    if (scene_.state.shading == Shading::Gouraud) t.gouraud[k] = &gouraud_[t.prim->object][tri[k]];
  }
  if (scene_.state.shading != Shading::Flat) return;
  // Flat: lit once, at the original triangle's centroid, with its face normal. Without
  // lights shadePrepared() returns the material's ambient term (and zero specular) for
  // any point and normal, so those are needed only when tracing (traceTerms()).
  if (t.shading->lights.empty() && trace_ == nullptr) {
    t.flat = LitColor{t.shading->ambient, glm::dvec3(0.0)};
  } else {
    const FlatFace face = flatFace(t.v[0]->world, t.v[1]->world, t.v[2]->world);
    t.centroid = face.centroid;
    t.face_normal = face.normal;
    t.flat = shadePrepared(*t.shading, t.centroid, t.face_normal);
  }
  t.constant = t.texture == nullptr && !t.pass->blend;
  if (t.constant && t.shading->lights.empty() && trace_ == nullptr) {
    const std::array<float, 4>& c = unlit_stored_[obj.material];
    for (int k = 0; k < 4; ++k) t.constant_stored[k] = c[k];
  } else if (t.constant) {
    const glm::dvec4 c = finalColor(t.flat, glm::dvec3(1.0), t.material->opacity);
    for (int k = 0; k < 4; ++k) t.constant_stored[k] = storeColor(c[k], color_format_);
  }
}

// drawPolygon()'s per-vertex work for one vertex (clip coordinates and error bound in `c`):
// false where drawPolygon() drops the polygon (w <= 0, only a degenerate camera gets
// there, or a non-finite window position). reach and depth_reach only with the
// uncertainty channels.
inline bool Renderer::windowVertexSetup(const ClipVertex& c, WindowVertex& wv, FixedVertex& fv,
                                        double& reach, double& depth_reach) const {
  if (!(c.clip.w > 0.0)) return false;
  wv = toWindow(c, scene_.width, scene_.height);
  if (!std::isfinite(wv.x) || !std::isfinite(wv.y) || !std::isfinite(wv.z)) return false;
  fv = snapVertexScaled(wv.x, wv.y, snap_scale_);
  if (shift_.active) {  // the sample position lands on the pixel centre
    fv.x -= shift_.units_x;
    fv.y -= shift_.units_y;
  }
  if (uncertainty_) {
    vertexReach(c, reach, depth_reach);
  } else {
    reach = depth_reach = 0.0;  // not read
  }
  return true;
}

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

WindowSetup Renderer::windowSetup() const {
  WindowSetup setup;
  setup.width = scene_.width;
  setup.height = scene_.height;
  setup.snap_scale = snap_scale_;
  setup.volume = volume_;
  if (shift_.active) {
    setup.shift_x = shift_.units_x;
    setup.shift_y = shift_.units_y;
  }
  return setup;
}

void Renderer::setUpWindows(std::size_t object, const WindowSetup& setup, std::size_t begin,
                            std::size_t end, const TransformedVertex* records) {
  VertexWindow* out = windows_[object].data() + begin;
  const std::size_t count = end - begin;
  setUpVertexWindows(records, count, setup, out);
  if (!uncertainty_) return;
  for (std::size_t i = 0; i < count; ++i) {
    VertexWindow& w = out[i];
    if ((w.flags & VertexWindow::kDrawable) == 0) continue;
    vertexReach(ClipVertex{records[i].clip, glm::dvec3(0.0), records[i].clip_err}, w.reach,
                w.depth_reach);
  }
}

// Asks for the frame rows a small triangle drawn later in the pass will touch (prefetch.h:
// the rows of a soup's triangles are otherwise missed one triangle after another). Only
// triangles drawn from their vertices' window set-up, the ones drawTriangle() does not
// clip; a hint, so the output is the same without it.
inline void Renderer::prefetchRows(const PrimitiveRef& prim) {
  const auto& tri = scene_.objects[prim.object].mesh.triangles[prim.triangle];
  const VertexWindow* windows = windows_[prim.object].data();
  const VertexWindow& a = windows[tri[0]];
  // Next to the last triangle asked about (a mesh in order): its rows are in the cache or
  // streaming in already, and the prefetches would only cost instructions. Tested first,
  // on one vertex, to keep that case cheap.
  const double dx = a.x - prefetch_x_;
  const double dy = a.y - prefetch_y_;
  prefetch_x_ = a.x;
  prefetch_y_ = a.y;
  if (std::fabs(dx) <= PrefetchBox::kMaxColumns && std::fabs(dy) <= 1.0) return;
  const VertexWindow& b = windows[tri[1]];
  const VertexWindow& c = windows[tri[2]];
  constexpr unsigned kFastPath = VertexWindow::kInside | VertexWindow::kDrawable;
  if ((a.flags & b.flags & c.flags & kFastPath) != kFastPath) return;
  const FixedVertex fixed[3] = {a.fixed, b.fixed, c.fixed};
  PixelBox box{};
  if (!PrefetchBox::worthPrefetching(fixed, options_.subpixel_bits, clip_, box)) return;
  // Rows are stored top down (fillSpans()): pixel (x, y) at (clip.y1 - 1 - y) * width + x -
  // clip.x0, so each row up is `width` elements back.
  const auto width = static_cast<std::ptrdiff_t>(fb_width_);
  std::ptrdiff_t begin = (clip_.y1 - 1 - box.row_begin) * width + (box.col_begin - clip_.x0);
  const std::ptrdiff_t count = box.col_end - box.col_begin;
  for (int py = box.row_begin; py < box.row_end; ++py, begin -= width) {
    const auto first = static_cast<std::size_t>(begin);
    const auto end = static_cast<std::size_t>(begin + count);
    prefetchSpan(frame_.color.data(), 4 * first, 4 * end);
    prefetchSpan(depth_.data(), first, end);
    prefetchSpan(frame_.id.data(), first, end);
    if (uncertainty_) gaps_.prefetch(first, end);
  }
}

void Renderer::drawTriangle(const PrimitiveRef& prim, const DrawPass& pass) {
  const Object& obj = scene_.objects[prim.object];
  const auto& tri = obj.mesh.triangles[prim.triangle];
  const std::vector<VertexWindow>& windows = windows_[prim.object];
  const VertexWindow* w[3] = {&windows[tri[0]], &windows[tri[1]], &windows[tri[2]]};
  const unsigned all = w[0]->flags & w[1]->flags & w[2]->flags;
  if (!(all & VertexWindow::kFinite)) return;  // NaN/Inf geometry: dropped
  if (all & VertexWindow::kInside) {
    // classifyTriangle()'s Inside case: the band can still drop it (every vertex beyond
    // the same side), else drawPolygon() of the whole triangle, with its per-vertex work
    // done once per vertex (setUpWindows()).
    if (all >> VertexWindow::kRejectShift) return;
    if (!(all & VertexWindow::kDrawable)) return;  // where drawPolygon() would return
    WindowVertex wv[3];
    FixedVertex fv[3];
    double reach[3];
    double depth_reach[3];
    for (int k = 0; k < 3; ++k) {
      wv[k] = WindowVertex{w[k]->x, w[k]->y, w[k]->z, w[k]->inv_w, glm::dvec3(0.0)};
      wv[k].bary[k] = 1.0;
      fv[k] = w[k]->fixed;
      reach[k] = w[k]->reach;
      depth_reach[k] = w[k]->depth_reach;
    }
    drawWindowed(prim, pass, wv, fv, reach, depth_reach, 3, false);
    return;
  }
  const std::vector<TransformedVertex>& verts = vertices_[prim.object];
  const glm::dvec4& c0 = verts[tri[0]].clip;
  const glm::dvec4& c1 = verts[tri[1]].clip;
  const glm::dvec4& c2 = verts[tri[2]].clip;
  switch (classifyTriangle(c0, c1, c2, volume_)) {
    case ClipClass::Rejected:
      return;
    case ClipClass::Inside: {  // not reached: every vertex inside is handled above
      const ClipVertex whole[3] = {{c0, {1.0, 0.0, 0.0}, verts[tri[0]].clip_err},
                                   {c1, {0.0, 1.0, 0.0}, verts[tri[1]].clip_err},
                                   {c2, {0.0, 0.0, 1.0}, verts[tri[2]].clip_err}};
      drawPolygon(prim, pass, whole, 3, false);
      return;
    }
    case ClipClass::Cut: {
      ClipPolygon poly;
      const glm::dvec4 errors[3] = {verts[tri[0]].clip_err, verts[tri[1]].clip_err,
                                    verts[tri[2]].clip_err};
      if (clipTriangle(c0, c1, c2, volume_, poly, errors))
        drawPolygon(prim, pass, poly.v.data(), poly.count, true);
      return;
    }
  }
}

// Draws the (clipped) polygon of one original triangle: window coordinates, snapping,
// culling, the uncertainty channels, then each fan triangle's coverage and fragments.
void Renderer::drawPolygon(const PrimitiveRef& prim, const DrawPass& pass, const ClipVertex* poly,
                           int count, bool clipped) {
  WindowVertex wv[kMaxClipVertices];
  FixedVertex fv[kMaxClipVertices];
  double reach[kMaxClipVertices];
  double depth_reach[kMaxClipVertices];
  for (int i = 0; i < count; ++i)
    if (!windowVertexSetup(poly[i], wv[i], fv[i], reach[i], depth_reach[i])) return;
  drawWindowed(prim, pass, wv, fv, reach, depth_reach, count, clipped);
}

// drawPolygon() from its vertices' window and snapped positions on: culling, the
// uncertainty channels, then each fan triangle's coverage and fragments.
void Renderer::drawWindowed(const PrimitiveRef& prim, const DrawPass& pass, const WindowVertex* wv,
                            const FixedVertex* fv, const double* reach, const double* depth_reach,
                            int count, bool clipped) {
  const bool ccw_is_front = scene_.state.front_face == FrontFace::CCW;
  const Cull cull = scene_.state.cull;
  auto culled = [&](bool ccw) {
    const bool front = ccw == ccw_is_front;
    return (cull == Cull::Back && !front) || (cull == Cull::Front && front);
  };

  if (uncertainty_) {
    double max_reach = 0.0;
    for (int i = 0; i < count; ++i) max_reach = std::max(max_reach, reach[i]);
    const double area2 = polygonArea2(wv, count);
    const bool rasterized = area2 != 0.0 && !culled(area2 > 0.0);
    if (rasterized || cullCouldFlip(wv, count, max_reach)) {
      if (shift_.active) {
        addSampleEdgeDistances(wv, count, reach);
      } else {
        edges_.add(wv, count, reach);  // addEdgeDistances(), deferred (EdgeDistanceBatch)
      }
    }
  }

  // Reused from the last triangle: these are the fields read before prepareTriangle() and
  // the per-fan set-up below write them; every other field is written before it is read
  // (see TriangleContext).
  TriangleContext& t = context_;
  t.prim = &prim;
  t.pass = &pass;
  t.constant = false;
  t.depth_slope = 0.0f;
  t.texel_choice = false;
  t.thin = false;
  t.short_normals = false;
  bool prepared = false;
  // The clipped polygon is drawn as a fan; each piece is culled by its own snapped area
  // (as GL implementations set up each post-clip triangle).
  for (int i = 1; i + 1 < count; ++i) {
    const std::int64_t area2 = snappedArea2(fv[0], fv[i], fv[i + 1]);
    if (area2 == 0 || culled(area2 > 0)) continue;
    TriangleCoverage coverage;
    if (!coverage.setup(fv[0], fv[i], fv[i + 1], options_.subpixel_bits, clip_)) continue;
    if (!prepared) {
      prepareTriangle(t);
      prepared = true;
    }
    FragmentInterpolator interp;
    // A triangle of one stored colour needs no barycentrics (unless traced).
    interp.setup(wv[0], wv[i], wv[i + 1], !t.constant || trace_ != nullptr);
    if (shift_.active) interp.shiftDepth(shift_.offset.x, shift_.offset.y);
    if (uncertainty_) {
      t.depth_slope = static_cast<float>(interp.depthSlope() * depth_steps_);
      t.depth_reach.setup(wv[0], wv[i], wv[i + 1], depth_reach[0], depth_reach[i],
                          depth_reach[i + 1]);
      // Not for the pieces of a clipped triangle: their clip vertices can lie 10^5 px away
      // (a near-plane cut), where the first-order bound grows to a tenth of the depth range
      // (docs/tolerances.md "Plane set-up": what is left uncovered there).
      if (!clipped) t.depth_reach.widen(planeSetupError(wv[0], wv[i], wv[i + 1]) * depth_steps_);
      t.texel_choice = t.texture != nullptr;
      t.thin = scene_.state.shading != Shading::Flat &&
               !(minAltitudePx(wv[0], wv[i], wv[i + 1]) >= kThinAltitudePx);
      if (scene_.state.shading == Shading::Phong) {
        t.short_normals = canBeShort(t.v[0]->normal, t.v[1]->normal, t.v[2]->normal, t.n_len_max);
        if (t.short_normals) {
          t.n_max = 0.0;
          for (const WindowVertex* w : {&wv[0], &wv[i], &wv[i + 1]}) {
            const glm::dvec3 n = w->bary.x * t.v[0]->normal + w->bary.y * t.v[1]->normal +
                                 w->bary.z * t.v[2]->normal;
            t.n_max = std::max(t.n_max, glm::length(n) * std::fabs(w->inv_w));
          }
        }
      }
      if (t.thin && scene_.state.shading == Shading::Gouraud) {
        for (int c = 0; c < 3; ++c) {
          t.ad_grad[c] = glm::dvec2(0.0);
          t.sp_grad[c] = glm::dvec2(0.0);
          for (int k = 0; k < 3; ++k) {
            t.ad_grad[c] += t.gouraud[k]->ambient_diffuse[c] * interp.numeratorGradient(k);
            t.sp_grad[c] += t.gouraud[k]->specular[c] * interp.numeratorGradient(k);
          }
        }
        t.den_grad = interp.denominatorGradient();
      }
      if (t.texel_choice && scene_.state.texture_filter == TextureFilter::Linear)
        t.texture_range = textureRangeOf(t.texture);
      if (t.texel_choice) {
        t.uq_max = glm::dvec2(0.0);
        for (const WindowVertex* w : {&wv[0], &wv[i], &wv[i + 1]}) {
          const glm::dvec2 uv =
              w->bary.x * t.v[0]->uv + w->bary.y * t.v[1]->uv + w->bary.z * t.v[2]->uv;
          t.uq_max = glm::max(t.uq_max, glm::abs(uv * w->inv_w));
        }
      }
    }
    if (trace_ != nullptr) {
      switch (scene_.state.shading) {
        case Shading::Flat:
          traceSpans<Shading::Flat>(t, coverage, interp);
          break;
        case Shading::Gouraud:
          traceSpans<Shading::Gouraud>(t, coverage, interp);
          break;
        case Shading::Phong:
          traceSpans<Shading::Phong>(t, coverage, interp);
          break;
      }
      continue;
    }
    shadeFan(t, coverage, interp);
  }
}

// Multisampling: edge_dist from the sample position (out of line, so that the
// single-sample drawPolygon() compiles as it did before multisampling).
void Renderer::addSampleEdgeDistances(const WindowVertex* wv, int count, const double* reach) {
  WindowVertex moved[kMaxClipVertices];
  for (int i = 0; i < count; ++i) {
    moved[i] = wv[i];
    moved[i].x -= shift_.offset.x;
    moved[i].y -= shift_.offset.y;
  }
  addEdgeDistances(moved, count, clip_, fb_width_, fb_height_, frame_.edge_dist.data(), reach);
}

template <Shading kShading>
inline glm::dvec4 Renderer::fragmentColor(const TriangleContext& t, const glm::dvec3& b,
                                          ShadingTerms* terms, TexelNote* note,
                                          const FragmentInterpolator* interp,
                                          const FragmentInterpolator::Row* row, double dx) const {
  glm::dvec3 tex(1.0);
  glm::dvec2 uv(0.0);
  if (t.texture) {
    uv = b.x * t.v[0]->uv + b.y * t.v[1]->uv + b.z * t.v[2]->uv;
    tex = glm::dvec3(
        sampleTexture(*t.texture, uv, scene_.state.texture_filter, scene_.state.texture_wrap));
  }
  LitColor lit;
  if constexpr (kShading == Shading::Flat) {
    lit = t.flat;
  } else if constexpr (kShading == Shading::Gouraud) {
    lit.ambient_diffuse = b.x * t.gouraud[0]->ambient_diffuse +
                          b.y * t.gouraud[1]->ambient_diffuse + b.z * t.gouraud[2]->ambient_diffuse;
    lit.specular =
        b.x * t.gouraud[0]->specular + b.y * t.gouraud[1]->specular + b.z * t.gouraud[2]->specular;
  } else {
    const glm::dvec3 p = b.x * t.v[0]->world + b.y * t.v[1]->world + b.z * t.v[2]->world;
    const glm::dvec3 n =
        safeNormalize(b.x * t.v[0]->normal + b.y * t.v[1]->normal + b.z * t.v[2]->normal);
    lit = shadePrepared(*t.shading, p, n, terms);
  }
  const glm::dvec4 color = finalColor(lit, tex, t.material->opacity);
  if (note && t.texel_choice) *note = texelNote(t, uv, b, lit.ambient_diffuse, *interp, *row, dx);
  if constexpr (kShading == Shading::Gouraud) {
    if (note && t.thin) note->shade = gouraudReach(t, b, lit, tex, *interp, *row, dx);
  } else if constexpr (kShading == Shading::Phong) {
    if (note && t.thin) note->shade = phongReach(t, b, tex, lit, *interp, *row, dx);
    if (note && t.short_normals) {
      const glm::dvec3 p = b.x * t.v[0]->world + b.y * t.v[1]->world + b.z * t.v[2]->world;
      note->normal = normalReach(t, b, p, *interp, *row, dx);
    }
  }
  if (terms) {
    if constexpr (kShading != Shading::Phong) traceTerms(t, b, *terms);
    terms->texture = tex;
    terms->uv = uv;
    terms->color = color;
  }
  return color;
}

// How much of a fragment's colour stays in the pixel: its opacity when its pass blends,
// else all of it (the weight of the texel and reach channels it adds).
inline double blendWeight(const TriangleContext& t) {
  return t.pass->blend ? std::clamp(t.material->opacity, 0.0, 1.0) : 1.0;
}

// A reach as the float its channel stores: NaN (nothing known) as +inf (anything allowed).
inline float reachChannel(double reach) {
  return std::isnan(reach) ? std::numeric_limits<float>::infinity() : static_cast<float>(reach);
}

// sum_k |b_k|: 1 inside the triangle, more where the centre lies outside it.
inline double baryMagnitude(const glm::dvec3& b) {
  return std::fabs(b.x) + std::fabs(b.y) + std::fabs(b.z);
}

// shade_reach of a Gouraud fragment of a fan triangle thinner than kThinAltitudePx
// (TriangleContext::thin; docs/tolerances.md (b)): its colour T * AD + S
// follows planes through the triangle's vertices (AD and S interpolated; T, the texture,
// has its own channels). Another implementation's planes go through its snapped vertices:
// with each moved by up to d px, the plane's value at the pixel moves, to first order, by
// grad C . sum_k b_k delta_k, at most |grad C| * sum_k |b_k| * d (b the pixel's
// barycentrics: sum |b_k| = 1 inside the triangle, more where the centre is covered only by
// the snapped triangle, as at a sliver's edge). The largest channel's |grad C| * sum |b_k|
// in 8-bit units per px, weighted by alpha when the fragment is blended; infinite where it
// is not a number.
float Renderer::gouraudReach(const TriangleContext& t, const glm::dvec3& b, const LitColor& lit,
                             const glm::dvec3& tex, const FragmentInterpolator& interp,
                             const FragmentInterpolator::Row& row, double dx) const {
  // grad v = (sum_k a_k grad N_k - v grad D) / D for v = AD_c and S_c (the sums per
  // triangle: TriangleContext::ad_grad, sp_grad).
  const double inv = 1.0 / interp.invWAt(row, dx);
  double worst2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    const glm::dvec2 ad = (t.ad_grad[c] - lit.ambient_diffuse[c] * t.den_grad) * inv;
    const glm::dvec2 sp = (t.sp_grad[c] - lit.specular[c] * t.den_grad) * inv;
    const glm::dvec2 g = tex[c] * ad + sp;
    const double g2 = g.x * g.x + g.y * g.y;
    if (!(g2 <= worst2)) worst2 = g2;  // NaN kept (infinite below)
  }
  const double weight = blendWeight(t);
  const double reach = 255.0 * std::sqrt(worst2) * baryMagnitude(b) * weight;
  return reachChannel(reach);
}

// normal_reach of a Phong fragment whose interpolated normal can be short
// (TriangleContext::short_normals; docs/tolerances.md (a)), where it is shorter than half
// the longest vertex normal (0 elsewhere). A driver interpolates n = sum
// b_k N_k in float32 with an error e per component of some ulps of the magnitudes its
// planes hold: kNormalReach * (largest |N_k / w_k| / |1 / w| + |grad n| * image size),
// |e| <= sqrt(3) times that. Normalising moves the direction by at most 2 |e| / |n| (2 when
// |e| >= |n|). Each light's diffuse term moves by kd L att times that, its specular term by
// ks L att s times it (Blinn; Phong's reflected vector moves 4 times as much), s at least 1.
// 8-bit units, the largest channel, weighted by alpha when blended.
float Renderer::normalReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& p,
                            const FragmentInterpolator& interp,
                            const FragmentInterpolator::Row& row, double dx) const {
  const glm::dvec3 n = b.x * t.v[0]->normal + b.y * t.v[1]->normal + b.z * t.v[2]->normal;
  const double len = glm::length(n);
  // As long as the normal from planes is (at least half) as long as its vertices', the
  // relative term (a) covers its rounding; beyond, it grows as 1 / |n|.
  if (len >= 0.5 * t.n_len_max) return 0.0f;
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  double gradient = 0.0;
  for (int c = 0; c < 3; ++c) {
    const glm::dvec3 nc(t.v[0]->normal[c], t.v[1]->normal[c], t.v[2]->normal[c]);
    gradient = std::max(gradient, std::hypot(glm::dot(db[0], nc), glm::dot(db[1], nc)));
  }
  const double q = std::fabs(interp.invWAt(row, dx));
  const double image = std::max(scene_.width, scene_.height);
  const double e = std::sqrt(3.0) * kNormalReach * (t.n_max / q + gradient * image);
  const double direction = len > e ? 2.0 * e / len : 2.0;
  const PreparedShading& s = *t.shading;
  const double spec = std::max(s.shininess, 1.0) * (s.blinn ? 1.0 : 4.0);
  glm::dvec3 k(0.0);
  for (const PreparedLight& light : s.lights) {
    double att = 1.0;
    if (light.attenuated) {
      const double r = glm::length(light.position - p);
      att = s.attenuation == Attenuation::Inverse ? 1.0 / r : 1.0 / (r * r);
    }
    k += glm::abs(light.radiance) * att * (glm::abs(s.kd) + spec * glm::abs(s.ks));
  }
  const double weight = blendWeight(t);
  const double reach = 255.0 * direction * std::max({k.x, k.y, k.z}) * weight;
  return reachChannel(reach);
}

// shade_reach of a Phong fragment of a fan triangle thinner than kThinAltitudePx
// (TriangleContext::thin):
// the same first-order bound as gouraudReach(), sum |b_k| * |grad C|, with C = T * AD + S
// lit from the interpolated position and normal, which is not linear in them: grad C by
// forward differences along the barycentrics' screen derivatives, with a step that moves
// them by 1e-6 (the quotient is then within about 1e-6 of the derivative, relative, where
// the lighting is smooth; far inside what the bound is used for). The texture stays T (its
// change has the texel terms). 8-bit units per px, weighted by alpha when blended.
float Renderer::phongReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& tex,
                           const LitColor& lit, const FragmentInterpolator& interp,
                           const FragmentInterpolator::Row& row, double dx) const {
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  auto colour = [&](const glm::dvec3& q) {
    const glm::dvec3 p = q.x * t.v[0]->world + q.y * t.v[1]->world + q.z * t.v[2]->world;
    const glm::dvec3 n =
        safeNormalize(q.x * t.v[0]->normal + q.y * t.v[1]->normal + q.z * t.v[2]->normal);
    const LitColor l = shadePrepared(*t.shading, p, n);
    return l.ambient_diffuse * tex + l.specular;
  };
  const glm::dvec3 c0 = lit.ambient_diffuse * tex + lit.specular;
  glm::dvec3 g[2];
  for (int a = 0; a < 2; ++a) {
    const double scale = std::max({std::fabs(db[a].x), std::fabs(db[a].y), std::fabs(db[a].z)});
    if (!(scale > 0.0)) {  // no change along this axis (or NaN: below)
      g[a] =
          std::isnan(scale) ? glm::dvec3(std::numeric_limits<double>::infinity()) : glm::dvec3(0.0);
      continue;
    }
    const double h = 1e-6 / scale;  // px
    g[a] = (colour(b + h * db[a]) - c0) / h;
  }
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double n = std::sqrt(g[0][c] * g[0][c] + g[1][c] * g[1][c]);
    if (!(n <= worst)) worst = n;  // NaN kept (infinite below)
  }
  const double weight = blendWeight(t);
  const double reach = 255.0 * worst * baryMagnitude(b) * weight;
  return reachChannel(reach);
}

// The texel channels of a textured fragment (docs/tolerances.md (c), (d), (e)), in 8-bit
// units weighted by alpha when the fragment is blended: the gain (how much a texel unit
// moves the colour: the ambient and diffuse light on the texture); with linear filtering
// how far float rounding may move the sample (texels) and the colour range of every
// footprint within that reach; with nearest filtering how far (px) the sample is from a
// texel boundary beyond float rounding and how much the colour would change with the
// texel(s) across it.
TexelNote Renderer::texelNote(const TriangleContext& t, const glm::dvec2& uv, const glm::dvec3& b,
                              const glm::dvec3& ambient_diffuse, const FragmentInterpolator& interp,
                              const FragmentInterpolator::Row& row, double dx) const {
  const double weight = blendWeight(t);
  TexelNote note;
  note.gain = static_cast<float>(
      weight * std::max({ambient_diffuse.x, ambient_diffuse.y, ambient_diffuse.z, 0.0}));
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  const glm::dvec3 u(t.v[0]->uv.x, t.v[1]->uv.x, t.v[2]->uv.x);
  const glm::dvec3 v(t.v[0]->uv.y, t.v[1]->uv.y, t.v[2]->uv.y);
  const double w = t.texture->width;
  const double h = t.texture->height;
  const double q = interp.invWAt(row, dx);
  const double image = std::max(scene_.width, scene_.height);
  TexelAxis s;
  s.coord = uv.x * w;
  s.gradient = w * std::hypot(glm::dot(db[0], u), glm::dot(db[1], u));
  s.reach = kTexelCoordinateReach *
            (w * std::max(std::fabs(uv.x), t.uq_max.x / std::fabs(q)) + s.gradient * image);
  TexelAxis tt;
  tt.coord = uv.y * h;
  tt.gradient = h * std::hypot(glm::dot(db[0], v), glm::dot(db[1], v));
  tt.reach = kTexelCoordinateReach *
             (h * std::max(std::fabs(uv.y), t.uq_max.y / std::fabs(q)) + tt.gradient * image);
  if (scene_.state.texture_filter == TextureFilter::Linear) {
    // Where float32 interpolation may move the sample (reach, texels), the filter may
    // read any footprint within it: the colour range over all of them.
    const glm::dvec4 range = linearReachRange(*t.texture, uv, scene_.state.texture_wrap, s.reach,
                                              tt.reach, t.texture_range);
    double alt = 0.0;
    for (int c = 0; c < 3; ++c) alt = std::max(alt, std::fabs(ambient_diffuse[c] * range[c]));
    note.alt = static_cast<float>(255.0 * alt * weight);
    const double reach = s.reach + tt.reach;
    note.reach = reachChannel(reach);
    return note;
  }
  const TexelChoice choice = nearestTexelChoice(*t.texture, s, tt, scene_.state.texture_wrap, 1.0);
  note.dist = static_cast<float>(choice.dist_px);
  double alt = 0.0;
  for (int k = 0; k < choice.alternatives; ++k)
    for (int c = 0; c < 3; ++c)
      alt = std::max(alt, std::fabs(ambient_diffuse[c] * (choice.alt[k][c] - choice.chosen[c])));
  note.alt = static_cast<float>(255.0 * alt * weight);
  return note;
}

// The ambient and per-light terms of flat and Gouraud fragments (Phong records them
// while lighting). Gouraud interpolates each vertex's terms like AD and S.
void Renderer::traceTerms(const TriangleContext& t, const glm::dvec3& b,
                          ShadingTerms& terms) const {
  if (scene_.state.shading == Shading::Flat) {
    shadePrepared(*t.shading, t.centroid, t.face_normal, &terms);
    return;
  }
  ShadingTerms vt[3];
  for (int k = 0; k < 3; ++k) shadePrepared(*t.shading, t.v[k]->world, t.v[k]->normal, &vt[k]);
  terms.points.clear();
  for (int k = 0; k < 3; ++k) {
    terms.points.push_back(std::move(vt[k].points.front()));
    terms.points.back().weight = b[k];
  }
  terms.ambient = b.x * vt[0].ambient + b.y * vt[1].ambient + b.z * vt[2].ambient;
  terms.lights.assign(vt[0].lights.size(), LightTerms{});
  for (std::size_t i = 0; i < terms.lights.size(); ++i) {
    terms.lights[i].diffuse = b.x * vt[0].lights[i].diffuse + b.y * vt[1].lights[i].diffuse +
                              b.z * vt[2].lights[i].diffuse;
    terms.lights[i].specular = b.x * vt[0].lights[i].specular + b.y * vt[1].lights[i].specular +
                               b.z * vt[2].lights[i].specular;
  }
}

glm::dvec4 Renderer::storedColor(std::size_t index) const {
  const float* c = &frame_.color[4 * index];
  return glm::dvec4(loadColor(c[0], color_format_), loadColor(c[1], color_format_),
                    loadColor(c[2], color_format_), loadColor(c[3], color_format_));
}

inline void Renderer::writeColor(std::size_t index, const glm::dvec4& src, bool blend) {
  if (blend && defer_blends_) {  // the fragment loop has just kept this fragment
    kept_.back().color = src;
    return;
  }
  float* c = &frame_.color[4 * index];
  if (!blend) {
    for (int k = 0; k < 4; ++k) c[k] = storeColor(src[k], color_format_);
    return;
  }
  const glm::dvec4 out = blendSourceOver(src, storedColor(index), color_format_);
  for (int k = 0; k < 4; ++k) c[k] = storeColor(out[k], color_format_);
}

// Lane4 and Lane8 values stay inside shadePhongQuad() (everything it calls is inlined):
// -Wpsabi's note on passing 32-byte vectors without AVX does not apply (for the rest of the
// file: GCC also gives it at the end of the translation unit).
#pragma GCC diagnostic ignored "-Wpsabi"

// Untextured, unblended Phong fragments of one row, up to eight: what PhongQuads shades.
struct PhongQuad {
  static constexpr int kMax = 8;
  const FragmentInterpolator* interp = nullptr;
  const PreparedShading* shading = nullptr;
  glm::dvec3 world[3];   // the original vertices' world positions
  glm::dvec3 normal[3];  // and normals
  float* colors = nullptr;
  bool rgba8 = false;
  float alpha = 0.0f;  // the stored opacity
  int count = 0;       // fragments pending
  std::size_t index[kMax] = {};
  double dx[kMax] = {};
};

using Float4 = float __attribute__((vector_size(16)));

// Lanes 4h .. 4h + 3 of v.
template <class V>
[[gnu::always_inline]] inline Lane4 quarterOf(V v, int h) {
  if constexpr (std::is_same_v<V, Lane8>) {
    return h == 0 ? v.lo : v.hi;
  } else {
    return v;
  }
}

// rgba32f: fragments 0 .. n-1 of four (channels r, g, b per lane, each float(c) as the
// scalar cast rounds it), each fragment's four channels stored as one vector.
[[gnu::always_inline]] inline void storeRgba32f(float* colors, const std::size_t* index, int n,
                                                Lane4 cr, Lane4 cg, Lane4 cb, float alpha) {
  const Float4 r = __builtin_convertvector(cr, Float4);
  const Float4 g = __builtin_convertvector(cg, Float4);
  const Float4 b = __builtin_convertvector(cb, Float4);
  const Float4 a = {alpha, alpha, alpha, alpha};
  const Float4 rg_lo = __builtin_shufflevector(r, g, 0, 4, 1, 5);  // r0 g0 r1 g1
  const Float4 rg_hi = __builtin_shufflevector(r, g, 2, 6, 3, 7);  // r2 g2 r3 g3
  const Float4 ba_lo = __builtin_shufflevector(b, a, 0, 4, 1, 5);  // b0 a b1 a
  const Float4 ba_hi = __builtin_shufflevector(b, a, 2, 6, 3, 7);  // b2 a b3 a
  const Float4 px[4] = {__builtin_shufflevector(rg_lo, ba_lo, 0, 1, 4, 5),
                        __builtin_shufflevector(rg_lo, ba_lo, 2, 3, 6, 7),
                        __builtin_shufflevector(rg_hi, ba_hi, 0, 1, 4, 5),
                        __builtin_shufflevector(rg_hi, ba_hi, 2, 3, 6, 7)};
  for (int lane = 0; lane < n; ++lane)
    __builtin_memcpy(colors + 4 * index[lane], &px[lane], sizeof px[lane]);
}

// The pending fragments in the lanes of V (Lane4 for up to four, Lane8 for more).
template <class V>
[[gnu::always_inline]] inline void shadePhongLanes(const PhongQuad& q,
                                                   const FragmentInterpolator::Row& row) {
  // One load (a loop over the lanes compiled to a call of memcpy); unused lanes repeat the
  // first fragment.
  V dx;
  __builtin_memcpy(&dx, q.dx, sizeof dx);
  dx = selectLanes(lanesBelow<V>(q.count), dx, splatAs<V>(q.dx[0]));
  V b[3];
  q.interp->barycentricAtLanes(row, dx, b);
  const Vec3L<V> p = combineLanes(b[0], b[1], b[2], q.world[0], q.world[1], q.world[2]);
  const Vec3L<V> n =
      safeNormalizeLanes(combineLanes(b[0], b[1], b[2], q.normal[0], q.normal[1], q.normal[2]));
  const LitColorL<V> lit = shadePreparedLanes(*q.shading, p, n);
  const Vec3L<V> c = lit.ambient_diffuse + lit.specular;
  if (q.rgba8) {
    for (int k = 0; k < q.count; ++k) {
      float* out = q.colors + 4 * q.index[k];
      out[0] = storeColor(c.x[k], ColorFormat::RGBA8);
      out[1] = storeColor(c.y[k], ColorFormat::RGBA8);
      out[2] = storeColor(c.z[k], ColorFormat::RGBA8);
      out[3] = q.alpha;
    }
    return;
  }
  for (int h = 0; 4 * h < q.count; ++h)
    storeRgba32f(q.colors, &q.index[static_cast<std::size_t>(4 * h)], std::min(4, q.count - 4 * h),
                 quarterOf(c.x, h), quarterOf(c.y, h), quarterOf(c.z, h), q.alpha);
}

// The colour of the pending fragments: with b = barycentricAt(row, dx), the scalar form is
// store(ambient_diffuse + specular of shadePrepared(shading, b.x * w0 + b.y * w1 + b.z *
// w2, safeNormalize(b.x * n0 + b.y * n1 + b.z * n2))); here lane by lane the same
// operations (shading_lanes.h), in four lanes up to four fragments and in eight above (two
// independent halves the processor overlaps: the chain of divisions and square roots of
// one quad is long). Compiled twice, for x86-64's baseline and for AVX2 (no FMA), and
// picked at load time: the bits are the same either way, AVX2 only does four lanes per
// instruction where SSE2 does two.
__attribute__((target_clones("avx2", "default"))) void shadePhongQuad(
    const PhongQuad& q, const FragmentInterpolator::Row& row) {
  if (q.count <= 4) {
    shadePhongLanes<Lane4>(q, row);
  } else {
    shadePhongLanes<Lane8>(q, row);
  }
}

// The shade functor of fillSpans() for untextured, unblended Phong: fragments that passed
// are collected and coloured eight at a time, the rest at the end of each span (fillSpans()
// calls flush()). Deferring a colour write past later fragments of the span changes
// nothing: nothing in the loop reads colour, and a span's pixels are distinct.
class PhongQuads {
 public:
  PhongQuads(const TriangleContext& t, const FragmentInterpolator& interp, float* colors,
             bool rgba8, float alpha) {
    q_.interp = &interp;
    q_.shading = t.shading;
    for (int k = 0; k < 3; ++k) {
      q_.world[k] = t.v[k]->world;
      q_.normal[k] = t.v[k]->normal;
    }
    q_.colors = colors;
    q_.rgba8 = rgba8;
    q_.alpha = alpha;
  }
  TexelNote operator()(std::size_t index, const FragmentInterpolator::Row& row, double dx) {
    q_.index[q_.count] = index;
    q_.dx[q_.count] = dx;
    if (++q_.count == PhongQuad::kMax) flush(row);
    return TexelNote{};
  }
  void flush(const FragmentInterpolator::Row& row) {
    if (q_.count != 0) shadePhongQuad(q_, row);
    q_.count = 0;
  }

 private:
  PhongQuad q_;
};

// The fragment loop: for every covered pixel centre, depth (from the unsnapped plane,
// clamped, quantized), the depth test, the uncertainty bookkeeping, then depth, id and
// colour writes. `shade(index, row, dx)` writes the colour of a fragment that passed.
// Everything constant along a row is computed once per row (FragmentInterpolator::Row).
template <DepthFormat kFormat, bool kGaps, bool kBarycentrics, class Shade>
void Renderer::fillSpans(const TriangleContext& t, const TriangleCoverage& coverage,
                         const FragmentInterpolator& interp, Shade&& shade) {
  const bool always = t.pass->depth_func == DepthFunc::Always;
  const bool depth_write = t.pass->depth_write;
  const bool blend = t.pass->blend;
  const bool keep = blend && defer_blends_;
  const float slope = t.depth_slope;
  const auto alpha = static_cast<float>(std::clamp(t.material->opacity, 0.0, 1.0));
  const std::uint32_t id = t.prim->id;
  std::uint32_t* const depth = depth_.data();
  std::uint32_t* const ids = frame_.id.data();
  ++triangles_drawn_;
  coverage.forEachSpan([&](int py, int x_begin, int x_end) {
    fragments_ += static_cast<std::uint64_t>(x_end - x_begin);
    const double cy = py + 0.5;  // pixel centres
    const FragmentInterpolator::Row row = kBarycentrics ? interp.row(cy) : interp.depthRow(cy);
    const std::size_t row_index =
        static_cast<std::size_t>(clip_.y1 - 1 - py) * static_cast<std::size_t>(fb_width_);
    // In a local: the depth and id stores (std::uint32_t) may alias clip_.x0 (int), so the
    // member would be reloaded for every fragment.
    const int x0 = clip_.x0;
    for (int px = x_begin; px < x_end; ++px) {
      const double dx = interp.dx(px + 0.5);
      const std::size_t index = row_index + static_cast<std::size_t>(px - x0);
      const double z = clampDepth(interp.depthAt(row, dx));
      const std::uint32_t key = depthKey(z, kFormat);  // kFormat constant: the switch folds
      const bool pass = always || key < depth[index];
      if constexpr (kGaps) {
        const float reach = t.depth_reach.at(px + 0.5, cy);
        if (pass) {
          gaps_.passed(index, z, slope, reach, !always, depth_write, blend);
        } else {
          gaps_.failed(index, z, slope, reach, blend);
        }
      }
      if (!pass) continue;
      if (depth_write) depth[index] = key;
      if (keep) {  // blended later, in depth order (resolveABuffer)
        kept_.push_back({static_cast<std::uint32_t>(index), blend_seq_, id, slope, z});
        KeptFragment& kept = kept_.back();
        kept.alpha = alpha;
        kept.note = shade(index, row, dx);  // its colour goes to kept.color
        continue;
      }
      ids[index] = id;
      const TexelNote note = shade(index, row, dx);
      if constexpr (kGaps)
        gaps_.colourWritten(index, blend, alpha, note.dist, note.alt, note.gain, note.reach,
                            note.shade, note.normal);
    }
    if constexpr (requires { shade.flush(row); }) shade.flush(row);
  });
}

template <DepthFormat kFormat>
void Renderer::shadeFanFormat(const TriangleContext& t, const TriangleCoverage& coverage,
                              const FragmentInterpolator& interp) {
  auto fill = [&](auto&& shade) {
    if (uncertainty_) {
      fillSpans<kFormat, true, true>(t, coverage, interp, shade);
    } else {
      fillSpans<kFormat, false, true>(t, coverage, interp, shade);
    }
  };
  float* const colors = frame_.color.data();
  const bool blend = t.pass->blend;
  if (t.constant) {  // one stored colour for the whole triangle
    const float c0 = t.constant_stored[0];
    const float c1 = t.constant_stored[1];
    const float c2 = t.constant_stored[2];
    const float c3 = t.constant_stored[3];
    auto shade = [=](std::size_t index, const FragmentInterpolator::Row&, double) {
      float* c = colors + 4 * index;
      c[0] = c0;
      c[1] = c1;
      c[2] = c2;
      c[3] = c3;
      return TexelNote{};
    };
    if (uncertainty_) {  // only the depth plane was set up
      fillSpans<kFormat, true, false>(t, coverage, interp, shade);
    } else {
      fillSpans<kFormat, false, false>(t, coverage, interp, shade);
    }
    return;
  }
  // Untextured, unblended Gouraud and Phong: fragmentColor() and writeColor() written out
  // with the triangle's constants in locals (the same expressions: an untextured colour is
  // (ambient + diffuse) * 1 + specular, and x * 1 == x exactly).
  // (Phong fans that record shade_reach take the general path.)
  if (t.texture == nullptr && !blend && scene_.state.shading != Shading::Flat &&
      !(uncertainty_ && (t.thin || t.short_normals) && scene_.state.shading == Shading::Phong)) {
    const bool rgba8 = color_format_ == ColorFormat::RGBA8;
    const float alpha = storeColor(t.material->opacity, color_format_);
    auto store = [=](std::size_t index, const glm::dvec3& c) {
      float* out = colors + 4 * index;
      if (rgba8) {
        out[0] = storeColor(c.x, ColorFormat::RGBA8);
        out[1] = storeColor(c.y, ColorFormat::RGBA8);
        out[2] = storeColor(c.z, ColorFormat::RGBA8);
      } else {
        out[0] = static_cast<float>(c.x);
        out[1] = static_cast<float>(c.y);
        out[2] = static_cast<float>(c.z);
      }
      out[3] = alpha;
    };
    if (scene_.state.shading == Shading::Gouraud) {
      const LitColor g0 = *t.gouraud[0];
      const LitColor g1 = *t.gouraud[1];
      const LitColor g2 = *t.gouraud[2];
      // Two loops: the shade_reach of thin triangles (uncertainty channels) in its own, so
      // that every other triangle's loop is the one without it.
      auto gouraud = [&](auto reach) {
        fill([&](std::size_t index, const FragmentInterpolator::Row& row, double dx) {
          const glm::dvec3 b = interp.barycentricAt(row, dx);
          const glm::dvec3 ad =
              b.x * g0.ambient_diffuse + b.y * g1.ambient_diffuse + b.z * g2.ambient_diffuse;
          const glm::dvec3 sp = b.x * g0.specular + b.y * g1.specular + b.z * g2.specular;
          store(index, ad + sp);
          TexelNote note;
          if constexpr (decltype(reach)::value)
            note.shade = gouraudReach(t, b, LitColor{ad, sp}, glm::dvec3(1.0), interp, row, dx);
          return note;
        });
      };
      if (uncertainty_ && t.thin) {
        gouraud(std::true_type{});
      } else {
        gouraud(std::false_type{});
      }
    } else {
      // Phong: four fragments at a time (shadePhongQuad() has the scalar form).
      PhongQuads quads(t, interp, colors, rgba8, alpha);
      fill(quads);
    }
    return;
  }
  // The general path; the texel note only where the uncertainty channels are kept.
  const bool notes = uncertainty_;
  auto general = [&](auto shading) {
    constexpr Shading kShading = decltype(shading)::value;
    fill([&](std::size_t index, const FragmentInterpolator::Row& row, double dx) {
      TexelNote note;
      const glm::dvec3 b = interp.barycentricAt(row, dx);
      writeColor(index,
                 fragmentColor<kShading>(t, b, nullptr, notes ? &note : nullptr, &interp, &row, dx),
                 blend);
      return note;
    });
  };
  switch (scene_.state.shading) {
    case Shading::Flat:
      general(std::integral_constant<Shading, Shading::Flat>{});
      break;
    case Shading::Gouraud:
      general(std::integral_constant<Shading, Shading::Gouraud>{});
      break;
    case Shading::Phong:
      general(std::integral_constant<Shading, Shading::Phong>{});
      break;
  }
}

void Renderer::shadeFan(const TriangleContext& t, const TriangleCoverage& coverage,
                        const FragmentInterpolator& interp) {
  switch (depth_format_) {
    case DepthFormat::D16:
      shadeFanFormat<DepthFormat::D16>(t, coverage, interp);
      break;
    case DepthFormat::D24:
      shadeFanFormat<DepthFormat::D24>(t, coverage, interp);
      break;
    case DepthFormat::D32F:
      shadeFanFormat<DepthFormat::D32F>(t, coverage, interp);
      break;
  }
}

// The fragment loop of tracePixel(): the same depth, test and writes as fillSpans() (the
// same expressions; FragmentInterpolator's per-pixel forms equal its row forms), with a
// FragmentTrace per fragment. The uncertainty channels are not computed when tracing.
template <Shading kShading>
void Renderer::traceSpans(const TriangleContext& t, const TriangleCoverage& coverage,
                          const FragmentInterpolator& interp) {
  const bool always = t.pass->depth_func == DepthFunc::Always;
  coverage.forEachSpan([&](int py, int x_begin, int x_end) {
    const double cy = py + 0.5;
    const std::size_t row =
        static_cast<std::size_t>(clip_.y1 - 1 - py) * static_cast<std::size_t>(fb_width_);
    for (int px = x_begin; px < x_end; ++px) {
      const double cx = px + 0.5;
      const std::size_t index = row + static_cast<std::size_t>(px - clip_.x0);
      const double z = clampDepth(interp.depth(cx, cy));
      const std::uint32_t key = depthKey(z, depth_format_);
      const std::uint32_t against = depth_[index];
      const bool pass = always || key < against;
      FragmentTrace f;
      f.primitive = t.prim->id;
      f.object = t.prim->object;
      f.barycentric = interp.barycentric(cx, cy);
      f.window_z = z;
      f.stored_z = storedDepth(key, depth_format_);
      f.depth_pass = pass;
      f.depth_against = storedDepth(against, depth_format_);
      const glm::dvec4 color = fragmentColor<kShading>(t, f.barycentric, &f.shading);
      if (pass) {
        if (t.pass->depth_write) depth_[index] = key;
        if (t.pass->blend && defer_blends_) {
          kept_.push_back({static_cast<std::uint32_t>(index), blend_seq_, t.prim->id, 0.0f, z});
        } else {
          frame_.id[index] = t.prim->id;
        }
        writeColor(index, color, t.pass->blend);
      }
      f.color_written = storedColor(index);
      trace_->push_back(std::move(f));
    }
  });
}

// The A-buffer's resolve: each pixel's kept fragments sorted far to near (window depth,
// ties in draw order: the order the sorted-triangle pass would blend them in), blended in
// that order through writeColor() (so that where the orders agree the colour is bit for
// bit the plain reference's), the nearest one as the id. Also the uncertainty channels of
// that order (UncertaintyTracker::sortedList) and which triangles the draw order blends
// out of depth order (abuffer_, for frame.json "abuffer").
void Renderer::resolveABuffer() {
  defer_blends_ = false;
  std::stable_sort(kept_.begin(), kept_.end(), [](const KeptFragment& a, const KeptFragment& b) {
    if (a.index != b.index) return a.index < b.index;
    if (a.z != b.z) return a.z > b.z;
    return a.seq < b.seq;
  });
  abuffer_.pixel_flags.assign(frame_.pixelCount(), 0);
  abuffer_.kept_fragments = kept_.size();
  std::vector<double> z;
  std::vector<float> slope;
  const std::size_t pairs_before = abuffer_.pair_pixels.size();
  for (std::size_t b = 0; b < kept_.size();) {
    std::size_t e = b;
    while (e < kept_.size() && kept_[e].index == kept_[b].index) ++e;
    const std::size_t index = kept_[b].index;
    abuffer_.pixel_flags[index] |= ABufferTally::kBlended;
    z.clear();
    slope.clear();
    for (std::size_t k = b; k < e; ++k) {
      const KeptFragment& f = kept_[k];
      writeColor(index, f.color, true);
      if (uncertainty_)
        gaps_.colourWritten(index, true, f.alpha, f.note.dist, f.note.alt, f.note.gain,
                            f.note.reach, f.note.shade, f.note.normal);
      z.push_back(f.z);
      slope.push_back(f.slope);
      if (sorted_ != nullptr) sorted_->push_back({f.id, f.seq, f.z, f.color, storedColor(index)});
    }
    frame_.id[index] = kept_[e - 1].id;
    if (uncertainty_) gaps_.sortedList(index, z.data(), slope.data(), z.size());
    // Inversions: a farther fragment (earlier in the list) drawn after a nearer one.
    for (std::size_t i = b; i < e; ++i) {
      for (std::size_t j = i + 1; j < e; ++j) {
        if (kept_[i].seq > kept_[j].seq && kept_[i].id != kept_[j].id) {
          abuffer_.pixel_flags[index] |= ABufferTally::kUnsorted;
          abuffer_.pair_pixels.push_back(
              {kept_[j].id, kept_[i].id, static_cast<std::uint32_t>(index)});
        }
      }
    }
    b = e;
  }
  // Each (pair, pixel) once: pixels come in increasing order, so sorting this frame's
  // entries keeps them grouped by pair and ordered by pixel within a pair.
  std::sort(abuffer_.pair_pixels.begin() + static_cast<std::ptrdiff_t>(pairs_before),
            abuffer_.pair_pixels.end());
  abuffer_.pair_pixels.erase(
      std::unique(abuffer_.pair_pixels.begin() + static_cast<std::ptrdiff_t>(pairs_before),
                  abuffer_.pair_pixels.end()),
      abuffer_.pair_pixels.end());
  kept_ = {};
}

// frame.json "abuffer" from a tally over the framebuffer rectangle `clip` of an image
// `image_height` rows high: pixel counts, and the out-of-order triangle pairs (most pixels
// first, ties by ids; each with the first pixel in framebuffer order, image coordinates).
nlohmann::json abufferMeta(ABufferTally& tally, const PixelRect& clip, int image_height) {
  std::uint64_t blended_pixels = 0;
  std::uint64_t unsorted_pixels = 0;
  for (const std::uint8_t f : tally.pixel_flags) {
    blended_pixels += (f & ABufferTally::kBlended) != 0 ? 1 : 0;
    unsorted_pixels += (f & ABufferTally::kUnsorted) != 0 ? 1 : 0;
  }
  std::vector<ABufferTally::PairPixel>& pp = tally.pair_pixels;
  std::sort(pp.begin(), pp.end());
  pp.erase(std::unique(pp.begin(), pp.end()), pp.end());
  struct PairCount {
    std::uint32_t near = 0;
    std::uint32_t far = 0;
    std::uint64_t pixels = 0;
    std::uint32_t first = 0;  // pixel index
  };
  std::vector<PairCount> list;
  for (const ABufferTally::PairPixel& p : pp) {
    if (list.empty() || list.back().near != p.near || list.back().far != p.far)
      list.push_back({p.near, p.far, 0, p.index});
    ++list.back().pixels;
  }
  std::stable_sort(list.begin(), list.end(),
                   [](const PairCount& a, const PairCount& b) { return a.pixels > b.pixels; });
  const auto width = static_cast<std::uint32_t>(clip.x1 - clip.x0);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < list.size() && k < kMaxReportedPairs; ++k) {
    const std::uint32_t first = list[k].first;
    const int x = clip.x0 + static_cast<int>(first % width);
    const int y = (image_height - clip.y1) + static_cast<int>(first / width);
    out.push_back({{"near", list[k].near},
                   {"far", list[k].far},
                   {"pixels", list[k].pixels},
                   {"first", {x, y}}});
  }
  return {{"kept_fragments", tally.kept_fragments},
          {"blended_pixels", blended_pixels},
          {"unsorted_pixels", unsorted_pixels},
          {"out_of_order_pairs", list.size()},
          {"out_of_order", std::move(out)}};
}

// How each uncertainty channel of a multisampled pixel follows from its samples' (a
// pixel may differ wherever one of its samples may): the smallest distance or gap, the
// largest slope, count or colour range.
constexpr bool kTakeSmallest[kUncertaintyChannels] = {
    true,   // edge_dist
    true,   // depth_gap
    false,  // depth_slope
    false,  // gap_slope
    true,   // texel_dist
    false,  // texel_alt
    false,  // blend_count
    true,   // blend_gap
    false,  // blend_slope
    true,   // clear_gap
    false,  // clear_slope
    false,  // texel_gain
    false,  // depth_reach
    false,  // texel_reach
    false,  // shade_reach
    false,  // normal_reach
};

// Multisampling: one render per sample (SampleShift), then the resolve: the colour is the
// mean of the samples' stored colours (converted to the colour format again), id, depth
// and coverage by resolveSampleOwners(), the uncertainty channels reduced over the
// samples (kTakeSmallest), per-sample edge_dist kept, and sample_alt.
Frame renderMultisample(const Scene& scene, const ReferenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const int samples = scene.state.samples;
  const bool given = !options.sample_positions.empty();
  const std::vector<glm::dvec2> positions =
      given ? options.sample_positions : standardSamplePositions(samples);
  if (static_cast<int>(positions.size()) != samples)
    throw InputError(sceneLabel(scene) + ": " + std::to_string(positions.size()) +
                     " sample positions given for " + std::to_string(samples) + " samples");
  for (const glm::dvec2& p : positions)
    if (!(p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0))
      throw InputError(sceneLabel(scene) + ": sample position outside the pixel [0, 1]^2");

  const double scale = std::ldexp(1.0, options.subpixel_bits);
  Frame out;
  std::vector<float> sample_color;  // per sample plane, RGBA
  std::vector<double> sum;
  std::uint64_t fragments = 0;
  std::uint64_t triangles = 0;
  bool on_grid = true;
  ABufferTally abuffer;  // ref:abuffer: the samples' resolves joined
  for (int s = 0; s < samples; ++s) {
    SampleShift shift;
    shift.active = true;
    shift.offset = positions[s] - glm::dvec2(0.5);
    const double ux = shift.offset.x * scale;
    const double uy = shift.offset.y * scale;
    shift.units_x = static_cast<std::int64_t>(roundHalfEven(ux));
    shift.units_y = static_cast<std::int64_t>(roundHalfEven(uy));
    on_grid = on_grid && static_cast<double>(shift.units_x) == ux &&
              static_cast<double>(shift.units_y) == uy;
    Renderer renderer(scene, options, PixelRect{0, 0, scene.width, scene.height}, nullptr, shift);
    Frame f = renderer.run();
    if (options.abuffer) {
      ABufferTally& t = renderer.abufferTally();
      if (s == 0) {
        abuffer = std::move(t);
      } else {
        for (std::size_t i = 0; i < t.pixel_flags.size(); ++i)
          abuffer.pixel_flags[i] |= t.pixel_flags[i];
        abuffer.pair_pixels.insert(abuffer.pair_pixels.end(), t.pair_pixels.begin(),
                                   t.pair_pixels.end());
        abuffer.kept_fragments += t.kept_fragments;
      }
    }
    const std::size_t n = f.pixelCount();
    fragments += f.meta["fragments"].get<std::uint64_t>();
    triangles = f.meta["triangles_rasterized"].get<std::uint64_t>();
    if (s == 0) {
      out.width = f.width;
      out.height = f.height;
      out.samples = samples;
      out.meta = f.meta;
      out.sample_id.resize(n * samples);
      out.sample_depth.resize(n * samples);
      sample_color.resize(n * 4 * samples);
      sum.assign(n * 4, 0.0);
      if (f.hasUncertainty()) {
        out.sample_edge_dist.resize(n * samples);
        const auto from = f.uncertainty();
        const auto to = out.uncertainty();
        for (int c = 0; c < kUncertaintyChannels; ++c) *to[c] = *from[c];
      }
    } else if (f.hasUncertainty()) {
      const auto from = f.uncertainty();
      const auto to = out.uncertainty();
      for (int c = 0; c < kUncertaintyChannels; ++c) {
        std::vector<float>& dst = *to[c];
        const std::vector<float>& src = *from[c];
        for (std::size_t i = 0; i < n; ++i)
          dst[i] = kTakeSmallest[c] ? std::min(dst[i], src[i]) : std::max(dst[i], src[i]);
      }
    }
    std::copy(f.id.begin(), f.id.end(), out.sample_id.begin() + static_cast<std::ptrdiff_t>(s * n));
    std::copy(f.depth.begin(), f.depth.end(),
              out.sample_depth.begin() + static_cast<std::ptrdiff_t>(s * n));
    std::copy(f.color.begin(), f.color.end(),
              sample_color.begin() + static_cast<std::ptrdiff_t>(s * n * 4));
    if (f.hasUncertainty())
      std::copy(f.edge_dist.begin(), f.edge_dist.end(),
                out.sample_edge_dist.begin() + static_cast<std::ptrdiff_t>(s * n));
    for (std::size_t k = 0; k < n * 4; ++k)
      sum[k] += loadColor(f.color[k], scene.state.color_format);
  }

  const std::size_t n = out.pixelCount();
  out.color.resize(n * 4);
  for (std::size_t k = 0; k < n * 4; ++k)
    out.color[k] = storeColor(sum[k] / samples, scene.state.color_format);
  resolveSampleOwners(out);
  if (out.hasUncertainty()) {
    // sample_alt: the colour range (8-bit units, any channel) over the samples of the pixel
    // and its eight neighbours.
    out.sample_alt.assign(n, 0.0f);
    const int w = out.width;
    const int h = out.height;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        float lo[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
        float hi[4] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
          for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
            const std::size_t j = out.index(xx, yy);
            for (int s = 0; s < samples; ++s) {
              const float* c = &sample_color[(static_cast<std::size_t>(s) * n + j) * 4];
              for (int k = 0; k < 4; ++k) {
                lo[k] = std::min(lo[k], c[k]);
                hi[k] = std::max(hi[k], c[k]);
              }
            }
          }
        }
        float range = 0.0f;
        for (int k = 0; k < 4; ++k)
          if (std::isfinite(hi[k] - lo[k])) range = std::max(range, hi[k] - lo[k]);
        out.sample_alt[out.index(x, y)] = 255.0f * range;
      }
    }
  }
  nlohmann::json pos = nlohmann::json::array();
  for (const glm::dvec2& p : positions) pos.push_back({p.x, p.y});
  out.meta["fragments"] = fragments;
  out.meta["triangles_rasterized"] = triangles;
  out.meta["multisample"] = {{"samples", samples},
                             {"positions", pos},
                             {"positions_source", given ? "given" : "standard"},
                             {"positions_on_grid", on_grid}};
  if (options.abuffer)
    out.meta["abuffer"] =
        abufferMeta(abuffer, PixelRect{0, 0, scene.width, scene.height}, scene.height);
  out.meta["timing_ms"]["render"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace

Frame renderReference(const Scene& scene, const ReferenceOptions& options) {
  validate(scene, options);
  Frame frame =
      scene.state.samples > 1
          ? renderMultisample(scene, options)
          : Renderer(scene, options, PixelRect{0, 0, scene.width, scene.height}, nullptr).run();
  frame.drawn = drawFacts(scene);  // what a comparison of this frame needs
  return frame;
}

std::vector<FragmentTrace> tracePixel(const Scene& scene, const ReferenceOptions& options, int x,
                                      int y_image) {
  validate(scene, options);
  if (x < 0 || x >= scene.width || y_image < 0 || y_image >= scene.height)
    throw InputError(sceneLabel(scene) + ": pixel " + std::to_string(x) + "," +
                     std::to_string(y_image) + " is outside the " + std::to_string(scene.width) +
                     "x" + std::to_string(scene.height) + " image");
  const int y = scene.height - 1 - y_image;  // GL window row
  std::vector<FragmentTrace> trace;
  Renderer renderer(scene, options, PixelRect{x, y, x + 1, y + 1}, &trace);
  renderer.run();
  return trace;
}

std::vector<SortedFragment> abufferPixel(const Scene& scene, ReferenceOptions options, int x,
                                         int y_image) {
  options.abuffer = true;
  validate(scene, options);
  if (x < 0 || x >= scene.width || y_image < 0 || y_image >= scene.height)
    throw InputError(sceneLabel(scene) + ": pixel " + std::to_string(x) + "," +
                     std::to_string(y_image) + " is outside the " + std::to_string(scene.width) +
                     "x" + std::to_string(scene.height) + " image");
  const int y = scene.height - 1 - y_image;
  std::vector<FragmentTrace> trace;
  std::vector<SortedFragment> sorted;
  Renderer renderer(scene, options, PixelRect{x, y, x + 1, y + 1}, &trace, SampleShift{}, &sorted);
  renderer.run();
  return sorted;
}

}  // namespace rc
