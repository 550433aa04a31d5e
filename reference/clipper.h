// Clipper: Sutherland-Hodgman in homogeneous clip space, in double, against the near
// and far planes (GL has no depth clamp here) and a guard band in x and y.
//
// The guard band exists only to keep the rasterizer's fixed-point edge functions inside
// int64: its planes lie far outside the viewport (see guardBand()), so clipping against
// them never changes which pixel centres are covered; the viewport itself is never a
// clip plane (the rasterizer's bounding box does that). Each output vertex carries its
// barycentric coordinates relative to the ORIGINAL triangle, so every attribute is
// interpolated from the original vertices and clipped pieces keep the primitive id.
// It does not divide by w, cull, or snap.
#pragma once

#include <array>
#include <cmath>

#include <glm/glm.hpp>

namespace rc::ref {

// Half-widths of the clip volume in x and y, as multiples of w: |x| <= guard_x * w.
// Window coordinates then stay within +/- limit_px (see guardBand()).
struct ClipVolume {
  double guard_x = 1.0;
  double guard_y = 1.0;
  // Trivial-reject band: a triangle entirely beyond +/- reject_x * w (or y) lies more than
  // two pixels outside the viewport and cannot cover (or come within a pixel of) any
  // pixel centre, so it is dropped before any clipping work.
  double reject_x = 1.0;
  double reject_y = 1.0;
};

// The guard band for a width x height viewport when window coordinates must stay within
// +/- limit_px pixels: with G = 2 * limit_px / size - 1, |x| <= G * w maps to window x in
// [size - limit_px, limit_px]. limit_px must exceed the viewport size (G > 1).
ClipVolume clipVolume(int width, int height, double limit_px);

struct ClipVertex {
  glm::dvec4 clip{0.0};
  glm::dvec3 bary{0.0};  // w.r.t. the original triangle's vertices 0, 1, 2
  // How far a float32 implementation's clip coordinates of this vertex may be from `clip`
  // (per component): the vertex transform's error for an original vertex; for one made by
  // clipping, what its two end points' errors and the float32 intersection add
  // (lerpFromInside()). Zero when nobody asked (no uncertainty channels).
  glm::dvec4 err{0.0};
};

// A convex polygon: each of the six planes adds at most one vertex to a triangle.
inline constexpr int kMaxClipVertices = 3 + 6;
struct ClipPolygon {
  std::array<ClipVertex, kMaxClipVertices> v{};
  int count = 0;
};

// What clipping will do with a triangle: drop it (entirely beyond the trivial-reject band,
// or entirely outside one plane), keep it whole (every vertex inside every plane), or cut
// it. The renderer draws `Inside` triangles without building a ClipPolygon; clipTriangle()
// makes the same decisions. Vertices must be finite.
enum class ClipClass { Rejected, Inside, Cut };
inline ClipClass classifyTriangle(const glm::dvec4& c0, const glm::dvec4& c1, const glm::dvec4& c2,
                                  const ClipVolume& v) {
  // Beyond +x / -x / +y / -y of the reject band, per vertex (bits AND-ed over the three).
  auto reject = [&](const glm::dvec4& c) {
    return (c.x > v.reject_x * c.w ? 1u : 0u) | (c.x < -v.reject_x * c.w ? 2u : 0u) |
           (c.y > v.reject_y * c.w ? 4u : 0u) | (c.y < -v.reject_y * c.w ? 8u : 0u);
  };
  // Inside every plane. For finite values d = a + b >= 0 exactly when a >= -b (a rounded
  // sum is zero only when the exact one is), so the six plane tests of clipper.cpp
  // (z + w, w - z, g w + x, g w - x, ...) >= 0 are |z| <= w, |x| <= g w, |y| <= g w.
  auto inside = [&](const glm::dvec4& c) {
    return std::fabs(c.z) <= c.w && std::fabs(c.x) <= v.guard_x * c.w &&
           std::fabs(c.y) <= v.guard_y * c.w;
  };
  if (inside(c0) && inside(c1) && inside(c2)) {  // the common case: only the band can drop it
    // reject() of the three vertices AND-ed, side by side (-(r w) == (-r) w exactly).
    const double x0 = v.reject_x * c0.w, x1 = v.reject_x * c1.w, x2 = v.reject_x * c2.w;
    const double y0 = v.reject_y * c0.w, y1 = v.reject_y * c1.w, y2 = v.reject_y * c2.w;
    const bool beyond =
        (c0.x > x0 && c1.x > x1 && c2.x > x2) || (c0.x < -x0 && c1.x < -x1 && c2.x < -x2) ||
        (c0.y > y0 && c1.y > y1 && c2.y > y2) || (c0.y < -y0 && c1.y < -y1 && c2.y < -y2);
    return beyond ? ClipClass::Rejected : ClipClass::Inside;
  }
  if (reject(c0) & reject(c1) & reject(c2)) return ClipClass::Rejected;
  // Outside each plane (distance < 0; see clipper.cpp's plane list), per vertex.
  auto outside = [&](const glm::dvec4& c) {
    return (c.z + c.w >= 0.0 ? 0u : 1u) | (c.w - c.z >= 0.0 ? 0u : 2u) |
           (v.guard_x * c.w + c.x >= 0.0 ? 0u : 4u) | (v.guard_x * c.w - c.x >= 0.0 ? 0u : 8u) |
           (v.guard_y * c.w + c.y >= 0.0 ? 0u : 16u) | (v.guard_y * c.w - c.y >= 0.0 ? 0u : 32u);
  };
  return (outside(c0) & outside(c1) & outside(c2)) ? ClipClass::Rejected : ClipClass::Cut;
}

// Clips the triangle (clip-space positions of the original vertices 0, 1, 2). Returns
// false (and count 0) when nothing of it is inside. Intersections are always computed
// from the inside vertex towards the outside one, so an edge shared by two triangles is
// cut at bit-identical points in both (no cracks along clipped shared edges).
// `errors` (optional): the three vertices' clip-space error bounds (ClipVertex::err).
// The segment a -> b clipped to `volume` in place (each end outside a plane moved to where
// it crosses it, with that point's float32 error as for polygons); false when nothing is
// left.
bool clipSegment(ClipVertex& a, ClipVertex& b, const ClipVolume& volume);

bool clipTriangle(const glm::dvec4& c0, const glm::dvec4& c1, const glm::dvec4& c2,
                  const ClipVolume& volume, ClipPolygon& out, const glm::dvec4* errors = nullptr);

}  // namespace rc::ref
