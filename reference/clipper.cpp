// Clipper: see clipper.h.
#include "reference/clipper.h"

namespace rc::ref {
namespace {

// Plane i: distance(c) >= 0 is inside.
enum Plane { kNear, kFar, kLeft, kRight, kBottom, kTop, kPlaneCount };

double distance(const glm::dvec4& c, int plane, const ClipVolume& vol) {
  switch (plane) {
    case kNear:
      return c.z + c.w;  // z >= -w
    case kFar:
      return c.w - c.z;  // z <= w
    case kLeft:
      return vol.guard_x * c.w + c.x;
    case kRight:
      return vol.guard_x * c.w - c.x;
    case kBottom:
      return vol.guard_y * c.w + c.y;
    default:
      return vol.guard_y * c.w - c.y;
  }
}

unsigned outcode(const glm::dvec4& c, const ClipVolume& vol) {
  unsigned code = 0;
  for (int p = 0; p < kPlaneCount; ++p)
    if (!(distance(c, p, vol) >= 0.0)) code |= 1u << p;
  return code;
}

ClipVertex lerpFromInside(const ClipVertex& in, double d_in, const ClipVertex& out, double d_out) {
  const double t = d_in / (d_in - d_out);
  return ClipVertex{in.clip + t * (out.clip - in.clip), in.bary + t * (out.bary - in.bary)};
}

}  // namespace

ClipVolume clipVolume(int width, int height, double limit_px) {
  ClipVolume v;
  v.guard_x = 2.0 * limit_px / width - 1.0;
  v.guard_y = 2.0 * limit_px / height - 1.0;
  v.reject_x = 1.0 + 4.0 / width;  // 2 px beyond the right (and left) edge
  v.reject_y = 1.0 + 4.0 / height;
  return v;
}

bool clipTriangle(const glm::dvec4& c0, const glm::dvec4& c1, const glm::dvec4& c2,
                  const ClipVolume& volume, ClipPolygon& out) {
  out.count = 0;
  if (classifyTriangle(c0, c1, c2, volume) == ClipClass::Rejected) return false;
  const unsigned o0 = outcode(c0, volume);
  const unsigned o1 = outcode(c1, volume);
  const unsigned o2 = outcode(c2, volume);

  out.v[0] = {c0, {1.0, 0.0, 0.0}};
  out.v[1] = {c1, {0.0, 1.0, 0.0}};
  out.v[2] = {c2, {0.0, 0.0, 1.0}};
  out.count = 3;
  const unsigned planes = o0 | o1 | o2;
  if (planes == 0) return true;

  std::array<ClipVertex, kMaxClipVertices> scratch{};
  for (int p = 0; p < kPlaneCount; ++p) {
    if (!(planes & (1u << p))) continue;
    int n = 0;
    for (int i = 0; i < out.count; ++i) {
      const ClipVertex& a = out.v[i];
      const ClipVertex& b = out.v[(i + 1) % out.count];
      const double da = distance(a.clip, p, volume);
      const double db = distance(b.clip, p, volume);
      const bool a_in = da >= 0.0;
      const bool b_in = db >= 0.0;
      // A convex polygon gains at most one vertex per plane; the capacity checks only
      // guard against rounding making a sliver non-convex.
      if (a_in && n < kMaxClipVertices) scratch[n++] = a;
      if (a_in != b_in && n < kMaxClipVertices) {
        scratch[n++] = a_in ? lerpFromInside(a, da, b, db) : lerpFromInside(b, db, a, da);
      }
    }
    out.v = scratch;
    out.count = n;
    if (out.count < 3) {
      out.count = 0;
      return false;
    }
  }
  return true;
}

}  // namespace rc::ref
