// The reference renderer's lines and points: line and point primitives, and triangles in
// polygon mode line or point. Each segment or point is clipped, set up in window
// coordinates and snapped like a triangle's vertices, rasterized by reference/line_raster.h
// (GL's diamond-exit rule, the column rule for wide lines, point squares), and every
// fragment goes through generalFragment(), the same per-fragment operations as triangles.
// The uncertainty channels get what GL leaves open about lines and points
// (docs/tolerances.md "Lines and points"): which pixels a segment's ends and its ties
// produce (edge_dist), and the interpolation parameter, which GL defines by projecting the
// fragment centre onto the segment while drivers interpolate along the major axis (up to
// half a pixel, more for wide lines, apart: depth_reach and normal_reach).
#include <algorithm>
#include <cmath>
#include <vector>

#include "fixtures/scene_geometry.h"
#include "reference/renderer_internal.h"

namespace rc::ref {
namespace {

// Calls f(px, py) for every pixel of `clip` in the columns (an x-major segment; else rows)
// within 1 + end_reach px of the segment's extent along its major axis whose centre lies
// within w / 2 + 1 px of the segment's line in the minor direction: every pixel a segment
// of rounded width w may produce or leave open.
template <class F>
void forEachPixelNear(const WindowVertex& a, const WindowVertex& b, double w, double end_reach,
                      const PixelRect& clip, F&& f) {
  const bool x_major = std::fabs(b.x - a.x) >= std::fabs(b.y - a.y);
  const double ma = x_major ? a.x : a.y;
  const double mb = x_major ? b.x : b.y;
  const double na = x_major ? a.y : a.x;
  const double nb = x_major ? b.y : b.x;
  const double lo = std::min(ma, mb);
  const double hi = std::max(ma, mb);
  const double slope = mb != ma ? (nb - na) / (mb - ma) : 0.0;
  const int major_lo = x_major ? clip.x0 : clip.y0;
  const int major_hi = x_major ? clip.x1 : clip.y1;
  const int minor_lo = x_major ? clip.y0 : clip.x0;
  const int minor_hi = x_major ? clip.y1 : clip.x1;
  const int first = std::max(major_lo, static_cast<int>(std::floor(lo - 1.5 - end_reach)));
  const int last = std::min(major_hi - 1, static_cast<int>(std::ceil(hi + 1.5 + end_reach)));
  for (int m = first; m <= last; ++m) {
    const double mc = m + 0.5;
    if (mc <= lo - 1.0 - end_reach || mc >= hi + 1.0 + end_reach) continue;
    const double n_line = na + (mc - ma) * slope;  // extrapolated past the ends
    const int n_first = std::max(minor_lo, static_cast<int>(std::floor(n_line - w / 2 - 1.5)));
    const int n_last = std::min(minor_hi - 1, static_cast<int>(std::ceil(n_line + w / 2 + 1.5)));
    for (int n = n_first; n <= n_last; ++n) {
      if (std::fabs(n + 0.5 - n_line) >= w / 2 + 1.0) continue;
      f(x_major ? m : n, x_major ? n : m);
    }
  }
}

// The point a fraction f of the way from a to b in window space: x, y, z and 1/w affine, the
// barycentrics divided by w too.
WindowVertex lerpWindow(const WindowVertex& a, const WindowVertex& b, double f) {
  WindowVertex v;
  v.x = a.x + f * (b.x - a.x);
  v.y = a.y + f * (b.y - a.y);
  v.z = a.z + f * (b.z - a.z);
  v.inv_w = a.inv_w + f * (b.inv_w - a.inv_w);
  v.bary = (a.bary * a.inv_w + f * (b.bary * b.inv_w - a.bary * a.inv_w)) / v.inv_w;
  return v;
}

// The window-space segment a -> b clipped to [0, width] x [0, height]: x, y, z and 1/w are
// affine along it in window space, the barycentrics divided by w too; false when nothing
// is left.
bool clipToViewport(WindowVertex& a, WindowVertex& b, int width, int height) {
  double t0 = 0.0;
  double t1 = 1.0;
  auto plane = [&](double d0, double d1) {
    if (d0 < 0.0 && d1 < 0.0) return false;
    if (d0 < 0.0) t0 = std::max(t0, d0 / (d0 - d1));
    if (d1 < 0.0) t1 = std::min(t1, d0 / (d0 - d1));
    return t0 <= t1;
  };
  if (!plane(a.x, b.x) || !plane(width - a.x, width - b.x) || !plane(a.y, b.y) ||
      !plane(height - a.y, height - b.y))
    return false;
  const WindowVertex from = a;
  const WindowVertex to = b;
  if (t0 > 0.0) a = lerpWindow(from, to, t0);
  if (t1 < 1.0) b = lerpWindow(from, to, t1);
  return true;
}

}  // namespace

void Renderer::prepareLine(TriangleContext& t, const std::uint32_t* vertices, int count) const {
  const Object& obj = scene_.objects[t.prim->object];
  t.material = &scene_.materials[obj.material];
  t.shading = &shading_[obj.material];
  t.texture = t.material->texture.get();
  t.chain = lod_ && t.texture != nullptr ? &chains_[obj.material] : nullptr;
  // v[0], v[1] the segment's ends (a point: its vertex twice); v[2] repeats the last.
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t vi = vertices[std::min(k, count - 1)];
    t.v[k] = &vertices_[t.prim->object][vi];
    if (scene_.state.shading == Shading::Gouraud) t.gouraud[k] = &gouraud_[t.prim->object][vi];
  }
  if (scene_.state.shading != Shading::Flat) return;
  const FlatFace face = flatSegment(t.v[0]->world, t.v[1]->world, t.v[0]->normal, t.v[1]->normal);
  t.centroid = face.centroid;
  t.face_normal = face.normal;
  t.flat = shadePrepared(*t.shading, t.centroid, t.face_normal);
}

void Renderer::drawLineOrPoint(const PrimitiveRef& prim, const DrawPass& pass) {
  const Object& obj = scene_.objects[prim.object];
  std::uint32_t vertices[3];
  const int count = primitiveVertices(obj, prim.triangle, vertices);
  const std::vector<VertexWindow>& windows = windows_[prim.object];
  for (int k = 0; k < count; ++k)
    if (!(windows[vertices[k]].flags & VertexWindow::kFinite)) return;  // NaN/Inf: dropped
  TriangleContext& t = context_;
  t.prim = &prim;
  t.pass = &pass;
  t.texel_choice = false;
  t.thin = false;
  t.short_normals = false;
  t.front_facing = true;  // lines and points are front-facing (stencil: the front state)
  t.offset = 0.0;         // polygon offset applies to polygons only
  t.offset_steps = 0.0f;
  prepareLine(t, vertices, count);
  const std::vector<TransformedVertex>& verts = vertices_[prim.object];
  if (count == 1) {
    const TransformedVertex& v = verts[vertices[0]];
    const ClipVertex c{v.clip, glm::dvec3(1.0, 0.0, 0.0), v.clip_err};
    const glm::dvec4& p = c.clip;
    WindowVertex wv{};
    FixedVertex fv{};
    double reach = 0.0;
    double depth_reach = 0.0;
    if (!windowVertexSetup(c, wv, fv, reach, depth_reach)) return;
    // GL discards a point whose centre is outside the view volume (13.7.1).
    if (std::fabs(p.z) > p.w) return;
    if (std::fabs(p.x) > p.w || std::fabs(p.y) > p.w) {
      // GL discards it; a driver that clips points as squares draws the part inside.
      if (uncertainty_) markAmbiguous(wv, wv, pass.ops.point_size / 2.0 + 1.0);
      return;
    }
    drawPointWindowed(wv, fv, reach, depth_reach, false);
    return;
  }
  const TransformedVertex& va = verts[vertices[0]];
  const TransformedVertex& vb = verts[vertices[1]];
  drawSegment(ClipVertex{va.clip, glm::dvec3(1.0, 0.0, 0.0), va.clip_err},
              ClipVertex{vb.clip, glm::dvec3(0.0, 1.0, 0.0), vb.clip_err}, false);
}

void Renderer::drawSegment(const ClipVertex& a, const ClipVertex& b, bool polygon_edge) {
  ClipVertex c0 = a;
  ClipVertex c1 = b;
  // To the view volume (GL 13.7: |x|, |y|, |z| <= w), not the guard band: a wide line is
  // widened from its clipped centre line, so the part of its width that reaches into the
  // viewport past the segment's exit is not drawn (llvmpipe and zink clip so). A clipped
  // end lies on the border, where GL's end rules leave the last fragments to the driver.
  ClipVolume view = volume_;
  view.guard_x = view.guard_y = 1.0;
  if (!clipSegment(c0, c1, view)) return;
  WindowVertex w0{};
  WindowVertex w1{};
  FixedVertex f0{};
  FixedVertex f1{};
  double r0 = 0.0;
  double r1 = 0.0;
  double d0 = 0.0;
  double d1 = 0.0;
  if (!windowVertexSetup(c0, w0, f0, r0, d0) || !windowVertexSetup(c1, w1, f1, r1, d1)) return;
  drawSegmentWindowed(w0, w1, f0, f1, std::max(r0, r1), std::max(d0, d1), polygon_edge);
}

// A polygon (a triangle, clipped) in polygon mode line or point: after culling by its
// facing, its boundary edges as segments, or its vertices as points. An edge made by
// clipping (its ends on different original edges) is not a boundary edge of the triangle
// and is not drawn, nor is a vertex made by clipping; GL leaves the edge flags of clipped
// polygons to the implementation (docs/reference.md "Lines and points").
void Renderer::drawPolygonOutline(const WindowVertex* wv, const FixedVertex* fv,
                                  const double* reach, const double* depth_reach, int count) {
  const DrawPass& pass = *context_.pass;
  std::int64_t area2 = 0;
  for (int i = 1; i + 1 < count; ++i) area2 += snappedArea2(fv[0], fv[i], fv[i + 1]);
  const bool front = (area2 > 0) == (pass.front_face == FrontFace::CCW);
  const bool culled = (area2 == 0 && pass.cull != Cull::None) ||
                      (pass.cull == Cull::Back && !front) || (pass.cull == Cull::Front && front);
  // A polygon so thin that float32 vertices could give its area the other sign: another
  // implementation may cull what this one draws, or draw what it culls.
  if (uncertainty_ && pass.cull != Cull::None) {
    double max_reach = 0.0;
    for (int i = 0; i < count; ++i) max_reach = std::max(max_reach, reach[i]);
    if (area2 == 0 || cullCouldFlip(wv, count, max_reach)) {
      const double radius = pass.ops.polygon_mode == PolygonMode::Point
                                ? pass.ops.point_size / 2.0 + 1.0
                                : roundedLineWidth(pass.ops.line_width) / 2.0 + 1.0;
      for (int i = 0; i < count; ++i) markAmbiguous(wv[i], wv[(i + 1) % count], radius);
    }
  }
  if (culled) return;
  TriangleContext& t = context_;
  t.front_facing = area2 == 0 || front;
  t.offset = 0.0;
  t.offset_steps = 0.0f;
  t.texel_choice = false;
  t.thin = false;
  t.short_normals = false;
  auto original = [](const glm::dvec3& b) {
    return (b.x == 1.0 && b.y == 0.0 && b.z == 0.0) || (b.x == 0.0 && b.y == 1.0 && b.z == 0.0) ||
           (b.x == 0.0 && b.y == 0.0 && b.z == 1.0);
  };
  // Where GL's polygon clipping and a driver's differ (docs/reference.md "Lines and
  // points"): the reference clips in a guard band and draws the triangle's own edges and
  // vertices; a driver may clip at the viewport (new vertices on its border, and edges
  // along it) and at the near and far planes, and draw those too. Their pixels are the
  // driver's choice: edges made by clipping, vertices made by clipping or beyond the
  // viewport, and where an edge crosses the viewport's border, the border there.
  const bool points = pass.ops.polygon_mode == PolygonMode::Point;
  // What a driver that clips at the viewport adds: vertices where the edges cross its
  // border, and edges along it between them (their depth and colour join the dry run).
  std::vector<WindowVertex> crossings;
  std::vector<std::pair<WindowVertex, WindowVertex>> border_edges;
  const double reach_px =
      points ? pass.ops.point_size / 2.0 + 1.0 : roundedLineWidth(pass.ops.line_width) / 2.0 + 1.0;
  if (uncertainty_) {
    const double bounds[2] = {static_cast<double>(scene_.width),
                              static_cast<double>(scene_.height)};
    double lo[2][2] = {{INFINITY, INFINITY}, {INFINITY, INFINITY}};  // [axis][side]
    double hi[2][2] = {{-INFINITY, -INFINITY}, {-INFINITY, -INFINITY}};
    WindowVertex border_lo[2][2]{};
    WindowVertex border_hi[2][2]{};
    for (int i = 0; i < count; ++i) {
      const WindowVertex& p = wv[i];
      const WindowVertex& q = wv[(i + 1) % count];
      const double pp[2] = {p.x, p.y};
      const double qq[2] = {q.x, q.y};
      for (int axis = 0; axis < 2; ++axis) {
        for (int side = 0; side < 2; ++side) {
          const double at = side == 0 ? 0.0 : bounds[axis];
          if ((pp[axis] - at) * (qq[axis] - at) > 0.0 || pp[axis] == qq[axis]) continue;
          const double f = (at - pp[axis]) / (qq[axis] - pp[axis]);
          const double other = pp[1 - axis] + f * (qq[1 - axis] - pp[1 - axis]);
          WindowVertex c = lerpWindow(p, q, f);
          (axis == 0 ? c.x : c.y) = at;
          (axis == 0 ? c.y : c.x) = other;
          markAmbiguous(c, c, reach_px);
          if (other < lo[axis][side]) {
            lo[axis][side] = other;
            border_lo[axis][side] = c;
          }
          if (other > hi[axis][side]) {
            hi[axis][side] = other;
            border_hi[axis][side] = c;
          }
          crossings.push_back(c);
        }
      }
    }
    if (!points) {
      for (int axis = 0; axis < 2; ++axis) {
        for (int side = 0; side < 2; ++side) {
          if (!(lo[axis][side] < hi[axis][side])) continue;
          markAmbiguous(border_lo[axis][side], border_hi[axis][side], reach_px);
          border_edges.emplace_back(border_lo[axis][side], border_hi[axis][side]);
        }
      }
    }
  }
  // GL does not order a polygon's edges (or vertices) among themselves: where two of them
  // produce the same pixel, which one is drawn last is the driver's choice (Mesa's draw
  // module starts with the edge from the last vertex). Those pixels' channels cover every
  // fragment the polygon puts there (outline_spread_).
  outline_shared_.clear();
  if (uncertainty_) {
    std::vector<std::size_t> hits;
    auto add = [&](const std::vector<LinePixel>& pixels) {
      for (const LinePixel& p : pixels) hits.push_back(frameIndex(p.x, p.y));
    };
    const double width = pass.ops.line_width;
    const double w = roundedLineWidth(width);
    const int bits = options_.subpixel_bits;
    for (int i = 0; i < count; ++i) {
      if (points) {  // every vertex: one made by clipping is a driver's point too
        add(pointCandidates(wv[i], pass.ops.point_size));
        continue;
      }
      const int j = (i + 1) % count;
      add(rasterizeWideLine(fv[i], fv[j], width, bits, clip_));
      add(endCandidates(wv[i], wv[j], w, halfLineWidth(width), std::max(reach[i], reach[j])));
    }
    if (points) {
      for (const WindowVertex& c : crossings) add(pointCandidates(c, pass.ops.point_size));
    } else {
      for (const auto& [a, b] : border_edges) {
        add(rasterizeWideLine(snapVertexScaled(a.x, a.y, snap_scale_),
                              snapVertexScaled(b.x, b.y, snap_scale_), 1.0, bits, clip_));
        add(endCandidates(a, b, w, halfLineWidth(width), 0.0));
      }
    }
    std::sort(hits.begin(), hits.end());
    for (std::size_t k = 1; k < hits.size(); ++k)
      if (hits[k] == hits[k - 1] && (outline_shared_.empty() || outline_shared_.back() != hits[k]))
        outline_shared_.push_back(hits[k]);
  }
  auto draw = [&] {
    if (outline_dry_) {
      for (const WindowVertex& c : crossings)
        if (points) drawPointWindowed(c, snapVertexScaled(c.x, c.y, snap_scale_), 0.0, 0.0, true);
      for (const auto& [a, b] : border_edges)
        if (!points)
          drawSegmentWindowed(a, b, snapVertexScaled(a.x, a.y, snap_scale_),
                              snapVertexScaled(b.x, b.y, snap_scale_), 0.0, 0.0, true);
    }
    if (points) {
      for (int i = 0; i < count; ++i) {
        const bool inside =
            wv[i].x >= 0.0 && wv[i].x <= scene_.width && wv[i].y >= 0.0 && wv[i].y <= scene_.height;
        // (The dry run also records a vertex beyond the viewport or made by clipping: a
        // driver may draw it.)
        if ((original(wv[i].bary) && inside) || outline_dry_) {
          drawPointWindowed(wv[i], fv[i], reach[i], depth_reach[i], true);
          if (!inside && uncertainty_) markAmbiguous(wv[i], wv[i], reach_px);
        } else if (uncertainty_) {
          markAmbiguous(wv[i], wv[i], reach_px);
        }
      }
      return;
    }
    for (int i = 0; i < count; ++i) {
      const int j = (i + 1) % count;
      bool boundary = false;
      for (int k = 0; k < 3; ++k)
        boundary = boundary || (wv[i].bary[k] == 0.0 && wv[j].bary[k] == 0.0);
      if (!boundary) {
        if (uncertainty_) markAmbiguous(wv[i], wv[j], reach_px);
        // The dry run records the edge clipping made: a driver may draw it, with its depths.
        if (outline_dry_)
          drawSegmentWindowed(wv[i], wv[j], fv[i], fv[j], std::max(reach[i], reach[j]),
                              std::max(depth_reach[i], depth_reach[j]), true);
        continue;
      }
      // Clipped to the viewport, as GL clips the polygon before it draws its edges (a wide
      // edge's band past the viewport's border is not drawn).
      WindowVertex a = wv[i];
      WindowVertex b = wv[j];
      if (!clipToViewport(a, b, scene_.width, scene_.height)) continue;
      const FixedVertex fa =
          a.x == wv[i].x && a.y == wv[i].y ? fv[i] : snapVertexScaled(a.x, a.y, snap_scale_);
      const FixedVertex fb =
          b.x == wv[j].x && b.y == wv[j].y ? fv[j] : snapVertexScaled(b.x, b.y, snap_scale_);
      drawSegmentWindowed(a, b, fa, fb, std::max(reach[i], reach[j]),
                          std::max(depth_reach[i], depth_reach[j]), true);
    }
  };
  // Shared pixels: a dry run records every fragment the polygon puts there (depth and
  // colour), whose spread then joins the channels of the fragments drawn there.
  outline_spread_.clear();
  if (!outline_shared_.empty()) {
    outline_dry_ = true;
    draw();
    outline_dry_ = false;
    std::sort(outline_spread_.begin(), outline_spread_.end(),
              [](const OutlineSpread& x, const OutlineSpread& y) { return x.index < y.index; });
    std::vector<OutlineSpread> merged;
    for (const OutlineSpread& f : outline_spread_) {
      if (merged.empty() || merged.back().index != f.index) {
        merged.push_back(f);
        continue;
      }
      OutlineSpread& m = merged.back();
      m.z_lo = std::min(m.z_lo, f.z_lo);
      m.z_hi = std::max(m.z_hi, f.z_hi);
      m.c_lo = glm::min(m.c_lo, f.c_lo);
      m.c_hi = glm::max(m.c_hi, f.c_hi);
    }
    outline_spread_ = std::move(merged);
  }
  draw();
  outline_shared_.clear();
  outline_spread_.clear();
}

// The pixels GL's end rules leave to the driver at the segment's two ends: in the columns
// (an x-major segment; else rows) within a pixel of an end point, those within w / 2 + 1 px
// of the segment in the minor direction.
std::vector<LinePixel> Renderer::endCandidates(const WindowVertex& a, const WindowVertex& b,
                                               double w, bool half, double end_reach) const {
  // Within kTieMarginPx of the rule's other decision: beyond any snapping or float32 error.
  constexpr double kTieMarginPx = 1.0 / 16.0;
  std::vector<LinePixel> out;
  forEachPixelNear(a, b, w, end_reach, clip_, [&](int px, int py) {
    if (segmentMargin(a, b, w, half, px + 0.5, py + 0.5, end_reach) < kTieMarginPx)
      out.push_back({px, py});
  });
  return out;
}

// The pixels a point of `size` at c may produce: centres within the square grown by half a
// pixel (the square's own, and those a tie on its border or the vertex's reach may add).
std::vector<LinePixel> Renderer::pointCandidates(const WindowVertex& c, double size) const {
  std::vector<LinePixel> out;
  const double h = size / 2.0 + 0.5;
  for (int py = std::max(clip_.y0, static_cast<int>(std::floor(c.y - h - 0.5)));
       py < std::min(clip_.y1, static_cast<int>(std::ceil(c.y + h + 0.5))); ++py) {
    for (int px = std::max(clip_.x0, static_cast<int>(std::floor(c.x - h - 0.5)));
         px < std::min(clip_.x1, static_cast<int>(std::ceil(c.x + h + 0.5))); ++px) {
      if (std::fabs(px + 0.5 - c.x) <= h && std::fabs(py + 0.5 - c.y) <= h) out.push_back({px, py});
    }
  }
  return out;
}

// Pixels whose centre lies within `radius` px (in x and in y) of the nearest point of the
// segment a -> b (a point when a == b):
// edge_dist 0, the driver's choice (no fragment of the reference's).
void Renderer::markAmbiguous(const WindowVertex& a, const WindowVertex& b, double radius) {
  const glm::dvec2 pa(a.x, a.y);
  const glm::dvec2 d = glm::dvec2(b.x, b.y) - pa;
  const double len2 = glm::dot(d, d);
  const int x0 = std::max(clip_.x0, static_cast<int>(std::floor(std::min(a.x, b.x) - radius)));
  const int x1 = std::min(clip_.x1, static_cast<int>(std::ceil(std::max(a.x, b.x) + radius)) + 1);
  const int y0 = std::max(clip_.y0, static_cast<int>(std::floor(std::min(a.y, b.y) - radius)));
  const int y1 = std::min(clip_.y1, static_cast<int>(std::ceil(std::max(a.y, b.y) + radius)) + 1);
  for (int py = y0; py < y1; ++py) {
    for (int px = x0; px < x1; ++px) {
      const glm::dvec2 c(px + 0.5, py + 0.5);
      const double t = len2 > 0.0 ? std::clamp(glm::dot(c - pa, d) / len2, 0.0, 1.0) : 0.0;
      const glm::dvec2 off = glm::abs(c - (pa + t * d));
      if (std::max(off.x, off.y) > radius) continue;  // squares: a point's shape
      frame_.edge_dist[frameIndex(px, py)] = 0.0f;
      if (options_.optional_cover != nullptr) (*options_.optional_cover)[frameIndex(px, py)] = 1;
    }
  }
}

void Renderer::drawSegmentWindowed(const WindowVertex& a, const WindowVertex& b,
                                   const FixedVertex& fa, const FixedVertex& fb, double reach,
                                   double depth_reach, bool polygon_edge) {
  const double width = context_.pass->ops.line_width;
  std::vector<LinePixel> pixels = rasterizeWideLine(fa, fb, width, options_.subpixel_bits, clip_);
  const double w = roundedLineWidth(width);
  const bool half = halfLineWidth(width);
  // The dry run of a polygon outline also records the fragments a driver may add at the
  // segment's ends and ties (another edge's pixel there may then hold this edge's depth and
  // colour).
  if (outline_dry_) {
    const std::vector<LinePixel> ends = endCandidates(a, b, w, half, reach);
    pixels.insert(pixels.end(), ends.begin(), ends.end());
  }
  // edge_dist: how close each pixel near the segment came to the other decision, less the
  // vertices' reach. In the segment's major direction, per column (x-major) or row: the
  // one-pixel rule produces the pixel whose centre is within w/2 of the segment measured
  // in the minor direction (the diamond test away from the ends; the column rule for
  // wide lines), so a pixel's margin is | |minor offset| - w/2 |. At each end, the columns
  // within a pixel of the end point are the driver's (GL's rules for the initial and
  // final fragments allow another fragment count and fragments one pixel away there).
  // A segment at 45 degrees to within its vertices' error may be x-major for a driver
  // and y-major here: a wide line's columns become rows, its ends another shape. Its whole
  // band is the driver's then.
  if (uncertainty_ && std::fabs(std::fabs(b.x - a.x) - std::fabs(b.y - a.y)) <=
                          2.0 * reach + 2.0 * std::ldexp(1.0, -options_.subpixel_bits)) {
    markAmbiguous(a, b, w / 2.0 + 1.0);
  }
  if (uncertainty_) {
    forEachPixelNear(a, b, w, reach, clip_, [&](int px, int py) {
      lowerEdgeDist(frameIndex(px, py),
                    segmentMargin(a, b, w, half, px + 0.5, py + 0.5, reach) - reach);
    });
  }
  if (pixels.empty()) return;
  if (!outline_dry_) ++triangles_drawn_;
  shadeLine(pixels, a, b, true, w, depth_reach, polygon_edge);
}

void Renderer::drawPointWindowed(const WindowVertex& c, const FixedVertex& fc, double reach,
                                 double depth_reach, bool polygon_vertex) {
  const double size = context_.pass->ops.point_size;
  // (A polygon outline's dry run: also the pixels a tie on the square's border may add.)
  const std::vector<LinePixel> pixels =
      outline_dry_ ? pointCandidates(c, size)
                   : rasterizePoint(fc, size, options_.subpixel_bits, clip_);
  // edge_dist: a pixel centre's distance to the square's border (inside or out), less the
  // vertex's reach: GL leaves centres on the border to the implementation.
  if (uncertainty_) {
    const double h = size / 2.0;
    // A square that crosses the viewport's border, or a polygon's vertex: Mesa's drivers
    // may draw it through their draw module (its clipper, its unfilled stage), whose
    // wide-point stage offsets it by (1/8, -1/8) px.
    const bool crosses =
        c.x - h < 0.0 || c.y - h < 0.0 || c.x + h > scene_.width || c.y + h > scene_.height;
    const double bias = crosses || polygon_vertex ? 0.125 : 0.0;
    for (int py = std::max(clip_.y0, static_cast<int>(std::floor(c.y - h - 1.5)));
         py < std::min(clip_.y1, static_cast<int>(std::ceil(c.y + h + 1.5))); ++py) {
      for (int px = std::max(clip_.x0, static_cast<int>(std::floor(c.x - h - 1.5)));
           px < std::min(clip_.x1, static_cast<int>(std::ceil(c.x + h + 1.5))); ++px) {
        const double d = pointMargin(c, size, px + 0.5, py + 0.5);
        if (d < 1.0) lowerEdgeDist(frameIndex(px, py), d - reach - bias);
      }
    }
  }
  if (pixels.empty()) return;
  if (!outline_dry_) ++triangles_drawn_;
  shadeLine(pixels, c, c, false, size, depth_reach, polygon_vertex);
}

}  // namespace rc::ref
