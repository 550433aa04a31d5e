// The reference renderer's draw loop: the scene's vertices transformed and set up once, then
// every pass of fixtures/scene_logic.h drawPasses() triangle by triangle through clipping,
// window set-up, snapping and culling to each fan triangle's coverage (docs/reference.md).
#include "reference/renderer_internal.h"

#include <chrono>
#include <functional>
#include <optional>
#include <string_view>

#include "fixtures/big_buffer.h"
#include "fixtures/mipmaps.h"
#include "fixtures/scene_geometry.h"
#include "reference/fragment_ops.h"
#include "reference/prefetch.h"

namespace rc::ref {
namespace {

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

}  // namespace

Renderer::Renderer(const Scene& scene, const ReferenceOptions& options, const PixelRect& clip,
                   std::vector<FragmentTrace>* trace, const SampleShift& shift,
                   std::vector<SortedFragment>* sorted)
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
      shift_(shift),
      lod_(lodSampling(scene.state)),
      lod_state_(lodState(scene.state)) {
  if (lod_) {
    for (const Material& m : scene.materials) {
      chain_storage_.push_back(mipChain(m));
      std::vector<const Texture*> chain;
      for (const auto& level : chain_storage_.back()) chain.push_back(level.get());
      chains_.push_back(std::move(chain));
    }
  }
  shading_.reserve(scene.materials.size());
  for (const Material& m : scene.materials) shading_.push_back(prepareShading(lighting_, m));
  // prepareTriangle()'s colour of an unlit, untextured, unblended flat triangle: one per
  // material (the same expressions, computed once instead of per triangle).
  unlit_stored_.resize(scene.materials.size());
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const glm::dvec4 c = finalColor(LitColor{shading_[m].ambient, glm::dvec3(0.0)}, glm::dvec3(1.0),
                                    scene.materials[m].opacity);
    for (int k = 0; k < 4; ++k) unlit_stored_[m][k] = storeColor(c[k], color_format_);
  }
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
    if (primitiveCount(obj) == 0) {
      vertices_[o].clear();
      windows_[o].clear();
      continue;
    }
    const std::size_t n = obj.mesh.positions.size();
    vertices_[o].resize(n);
    windows_[o].resize(n);
    if (shading == Shading::Gouraud) gouraud_[o].resize(n);
    // Flat shading lights the face normal: vertex normals would go unused (unless traced).
    // (Flat line and point primitives light their vertices' normals: prepareLine().)
    const ObjectTransform transform(
        obj, camera_,
        shading != Shading::Flat || trace_ != nullptr || obj.primitive != PrimitiveKind::Triangles,
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
    // (Lines and points read their vertices' clip coordinates: line_loop.cpp.)
    bool records_unread = obj.primitive == PrimitiveKind::Triangles && shading == Shading::Flat &&
                          trace_ == nullptr && scene_.materials[obj.material].texture == nullptr &&
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
  if (options_.optional_cover != nullptr) options_.optional_cover->assign(frame_.pixelCount(), 0);
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
  const std::vector<DrawPass> passes = drawPasses(scene_, options_.force_painter);
  general_ops_ =
      std::any_of(passes.begin(), passes.end(), [](const DrawPass& p) { return p.extended(); });
  if (general_ops_) {
    defer_blends_ = false;  // ref:abuffer sorts only the original transparency pass
    plane_keys_.assign(frame_.pixelCount(), 0);
  }
  if (scene_.state.stencil_format != StencilFormat::None)
    stencil_.assign(frame_.pixelCount(), static_cast<std::uint8_t>(scene_.clear_stencil));
  for (const DrawPass& pass : passes) {
    const std::vector<PrimitiveRef>& prims = pass.primitives;
    if (pass.primitive != DrawnPrimitive::Triangles) {
      for (const PrimitiveRef& prim : prims) drawLineOrPoint(prim, pass);
      continue;
    }
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
    if (general_ops_) {
      gaps_.finishConservative(frame_);
    } else {
      gaps_.finish(frame_);
    }
  }
  if (!stencil_.empty()) frame_.stencil.assign(stencil_.begin(), stencil_.end());

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
  // The reference's r is the format's minimum resolvable difference (frame.json of a GL
  // frame has the driver's, measured, in the same unit).
  if (std::any_of(passes.begin(), passes.end(),
                  [](const DrawPass& p) { return p.ops.polygon_offset.has_value(); }))
    frame_.meta["polygon_offset_r"] = 1.0;
  return std::move(frame_);
}

void Renderer::prepareTriangle(TriangleContext& t) const {
  const Object& obj = scene_.objects[t.prim->object];
  const auto& tri = obj.mesh.triangles[t.prim->triangle];
  t.material = &scene_.materials[obj.material];
  t.shading = &shading_[obj.material];
  t.texture = t.material->texture.get();
  t.chain = lod_ && t.texture != nullptr ? &chains_[obj.material] : nullptr;
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
  t.constant = t.texture == nullptr && !t.pass->blend && !options_.fragment_definition_only;
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
bool Renderer::windowVertexSetup(const ClipVertex& c, WindowVertex& wv, FixedVertex& fv,
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
  if (pass.ops.polygon_mode != PolygonMode::Fill) {  // its edges or vertices (line_loop.cpp)
    // (t.constant, the fans' one-colour fast path, is not read on the way: every fragment
    // goes through generalFragment().)
    TriangleContext& t = context_;
    t.prim = &prim;
    t.pass = &pass;
    prepareTriangle(t);
    drawPolygonOutline(wv, fv, reach, depth_reach, count);
    return;
  }
  const bool ccw_is_front = pass.front_face == FrontFace::CCW;
  const Cull cull = pass.cull;
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
      setUpFanChannels(t, interp, wv, depth_reach, i, clipped);
    }
    if (general_ops_) {
      setUpGeneralFan(t, interp, wv[0], wv[i], wv[i + 1], (area2 > 0) == ccw_is_front);
      shadeFanGeneral(t, coverage, interp);
      continue;
    }
    if (trace_ != nullptr) {
      traceFan(t, coverage, interp);
      continue;
    }
    shadeFan(t, coverage, interp);
  }
}

void Renderer::setUpGeneralFan(TriangleContext& t, const FragmentInterpolator& interp,
                               const WindowVertex& a, const WindowVertex& b, const WindowVertex& c,
                               bool front_facing) {
  const DrawPass& pass = *t.pass;
  t.front_facing = front_facing;
  const glm::dvec2 range = pass.ops.depth_range;
  const double scale = range.y - range.x;  // window z = n + (f - n) z01
  t.offset = 0.0;
  t.offset_steps = 0.0f;
  double offset_reach = 0.0;  // steps
  if (pass.ops.polygon_offset) {
    // m = max(|dz/dx|, |dz/dy|): the estimate GL allows at the low end, and what Mesa's
    // drivers use; the spec's upper bound |dz/dx| + |dz/dy| is the rest of the reach.
    const glm::dvec2 g = interp.depthGradient() * scale;
    const double m = std::max(std::fabs(g.x), std::fabs(g.y));
    const double max_z =
        std::max({range.x + scale * a.z, range.x + scale * b.z, range.x + scale * c.z});
    const double r = minimumResolvableDepth(depth_format_, max_z);
    const PolygonOffset& o = *pass.ops.polygon_offset;
    t.offset = m * o.factor + r * o.units;
    // r is the implementation's: what another r moves the depth by is the comparator's
    // (offset_steps x the measured spread of r, docs/tolerances.md "Polygon offset").
    t.offset_steps = static_cast<float>(std::fabs(o.units) * r * depth_steps_);
    offset_reach = std::fabs(o.factor) * (std::fabs(g.x) + std::fabs(g.y) - m) * depth_steps_;
    // d32f: r follows the exponent of the depth, which implementations may take per
    // fragment instead of per polygon.
    if (depth_format_ == DepthFormat::D32F) offset_reach += std::fabs(o.units) * r * depth_steps_;
    // The offset added in float32 to a depth below 1: a rounding of at most a step.
    offset_reach += 1.0;
  }
  // A depth range other than [0, 1]: the viewport's z scale and bias in float32.
  if (range != glm::dvec2(0.0, 1.0)) offset_reach += 1.0;
  if (uncertainty_ && offset_reach > 0.0) t.depth_reach.widen(offset_reach);
  // The bits of what decides the plane's depths, hashed (a collision can only make one
  // comparison count as invariant: 1 in 2^64).
  const double planes[12] = {a.x, a.y, a.z, b.x,     b.y,     b.z,
                             c.x, c.y, c.z, range.x, range.y, t.offset};
  const std::size_t h = std::hash<std::string_view>{}(
      std::string_view(reinterpret_cast<const char*>(planes), sizeof planes));
  t.plane_key = h == 0 ? 1 : h;
}

}  // namespace rc::ref
