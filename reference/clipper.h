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
};

// A convex polygon: each of the six planes adds at most one vertex to a triangle.
inline constexpr int kMaxClipVertices = 3 + 6;
struct ClipPolygon {
  std::array<ClipVertex, kMaxClipVertices> v{};
  int count = 0;
};

// Clips the triangle (clip-space positions of the original vertices 0, 1, 2). Returns
// false (and count 0) when nothing of it is inside. Intersections are always computed
// from the inside vertex towards the outside one, so an edge shared by two triangles is
// cut at bit-identical points in both (no cracks along clipped shared edges).
bool clipTriangle(const glm::dvec4& c0, const glm::dvec4& c1, const glm::dvec4& c2,
                  const ClipVolume& volume, ClipPolygon& out);

}  // namespace rc::ref
