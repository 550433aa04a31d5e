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

// The error of a plane distance computed in float32 from clip coordinates off by `err`.
double distanceError(const glm::dvec4& c, const glm::dvec4& err, int plane, const ClipVolume& vol) {
  constexpr double u = 0x1p-24;
  switch (plane) {
    case kNear:
    case kFar:
      return err.z + err.w + u * (std::fabs(c.z) + std::fabs(c.w));
    case kLeft:
    case kRight:
      return vol.guard_x * err.w + err.x + u * (vol.guard_x * std::fabs(c.w) + std::fabs(c.x));
    default:
      return vol.guard_y * err.w + err.y + u * (vol.guard_y * std::fabs(c.w) + std::fabs(c.y));
  }
}

// The intersection of edge in-out with the plane. Its error bound, for a float32
// implementation: t = d_in / (d_in - d_out) moves by
// (|d_out| e_in + |d_in| e_out) / (d_in - d_out)^2 (plus its own rounding) when the
// distances are off by e_in, e_out; the point by that times |out - in|, plus the end
// points' own errors and the interpolation's rounding.
ClipVertex lerpFromInside(const ClipVertex& in, double d_in, const ClipVertex& out, double d_out,
                          int plane, const ClipVolume& vol) {
  const double t = d_in / (d_in - d_out);
  ClipVertex v{in.clip + t * (out.clip - in.clip), in.bary + t * (out.bary - in.bary), {}};
  if (in.err != glm::dvec4(0.0) || out.err != glm::dvec4(0.0)) {
    constexpr double u = 0x1p-24;
    const double e_in = distanceError(in.clip, in.err, plane, vol);
    const double e_out = distanceError(out.clip, out.err, plane, vol);
    const double span = d_in - d_out;
    const double dt = (std::fabs(d_out) * e_in + std::fabs(d_in) * e_out) / (span * span) +
                      4.0 * u * std::fabs(t);
    v.err = (1.0 - t) * in.err + t * out.err + dt * glm::abs(out.clip - in.clip) +
            2.0 * u * (glm::abs(in.clip) + glm::abs(t * (out.clip - in.clip)));
  }
  return v;
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
                  const ClipVolume& volume, ClipPolygon& out, const glm::dvec4* errors) {
  out.count = 0;
  if (classifyTriangle(c0, c1, c2, volume) == ClipClass::Rejected) return false;
  const unsigned o0 = outcode(c0, volume);
  const unsigned o1 = outcode(c1, volume);
  const unsigned o2 = outcode(c2, volume);

  out.v[0].clip = c0;
  out.v[1].clip = c1;
  out.v[2].clip = c2;
  out.v[0].bary = {1.0, 0.0, 0.0};
  out.v[1].bary = {0.0, 1.0, 0.0};
  out.v[2].bary = {0.0, 0.0, 1.0};
  for (int k = 0; k < 3; ++k) out.v[k].err = errors ? errors[k] : glm::dvec4(0.0);
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
        scratch[n++] = a_in ? lerpFromInside(a, da, b, db, p, volume)
                            : lerpFromInside(b, db, a, da, p, volume);
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

bool clipSegment(ClipVertex& a, ClipVertex& b, const ClipVolume& volume) {
  // Plane by plane, each end outside it moved to the crossing (Sutherland-Hodgman for two
  // vertices), with the intersection's error as for polygons.
  for (int p = 0; p < kPlaneCount; ++p) {
    const double da = distance(a.clip, p, volume);
    const double db = distance(b.clip, p, volume);
    const bool a_in = da >= 0.0;
    const bool b_in = db >= 0.0;
    if (!a_in && !b_in) return false;
    if (a_in && b_in) continue;
    if (a_in) {
      b = lerpFromInside(a, da, b, db, p, volume);
    } else {
      a = lerpFromInside(b, db, a, da, p, volume);
    }
  }
  return true;
}

}  // namespace rc::ref
