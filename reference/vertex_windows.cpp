// Per-vertex window set-up: see vertex_windows.h.
#include "reference/vertex_windows.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference/lanes.h"
#include "reference/viewport.h"

namespace rc::ref {
namespace {

// Lane4 values stay inside setUpVertexWindows() (everything it calls on them is inlined):
// -Wpsabi's note on passing 32-byte vectors without AVX does not apply (for the rest of the
// file: GCC also gives it at the end of the translation unit).
#pragma GCC diagnostic ignored "-Wpsabi"

[[gnu::always_inline]] inline Mask4 splatMask4(std::int64_t v) { return Mask4{v, v, v, v}; }

// |x| per lane (clears the sign bit, as std::fabs does).
[[gnu::always_inline]] inline Lane4 abs4(Lane4 x) {
  return reinterpret_cast<Lane4>(reinterpret_cast<Mask4>(x) & splatMask4(0x7fffffffffffffff));
}

// snapVertexScaled()'s roundHalfEven((v - 0.5) * scale) per lane (|v| < 2^52 rounds
// through 2^52, larger magnitudes are integers already), 0 where not `keep` (converted to
// int64 afterwards: only drawable vertices need it). A function, not a lambda: a lambda's
// body is compiled once, for the baseline, and called from the AVX2 build with 32-byte
// vectors where it is not inlined (-O0 crashed).
[[gnu::always_inline]] inline Lane4 snap4(Lane4 window, Lane4 scale, Mask4 keep) {
  const Lane4 two52 = splat4(4503599627370496.0);
  const Lane4 zero = splat4(0.0);
  const Lane4 v = (window - splat4(0.5)) * scale;
  const Lane4 up = (v + two52) - two52;
  const Lane4 down = (v - two52) + two52;
  const Lane4 r = abs4(v) < two52 ? (v >= zero ? up : down) : v;
  return keep ? r : zero;
}

// The body of both builds below (inlined into each, so compiled for each one's instructions).
[[gnu::always_inline]] inline void setUpLanes(const TransformedVertex* verts, std::size_t count,
                                              const WindowSetup& setup, VertexWindow* out) {
  const Lane4 inf = splat4(std::numeric_limits<double>::infinity());
  const Lane4 half = splat4(0.5);
  const Lane4 width = splat4(static_cast<double>(setup.width));
  const Lane4 height = splat4(static_cast<double>(setup.height));
  const Lane4 scale = splat4(setup.snap_scale);
  const Lane4 zero = splat4(0.0);
  for (std::size_t i = 0; i < count; i += 4) {
    const std::size_t n = std::min<std::size_t>(4, count - i);
    Lane4 cx;
    Lane4 cy;
    Lane4 cz;
    Lane4 cw;
    for (std::size_t k = 0; k < 4; ++k) {  // lanes past the end repeat the first vertex
      const glm::dvec4& c = verts[i + (k < n ? k : 0)].clip;
      cx[k] = c.x;
      cy[k] = c.y;
      cz[k] = c.z;
      cw[k] = c.w;
    }
    // std::isfinite(v) is |v| < inf (false for NaN).
    const Mask4 finite = (abs4(cx) < inf) & (abs4(cy) < inf) & (abs4(cz) < inf) & (abs4(cw) < inf);
    // classifyTriangle(): inside every plane, and beyond which side of the reject band.
    const Mask4 inside = (abs4(cz) <= cw) & (abs4(cx) <= splat4(setup.volume.guard_x) * cw) &
                         (abs4(cy) <= splat4(setup.volume.guard_y) * cw);
    const Lane4 rx = splat4(setup.volume.reject_x) * cw;
    const Lane4 ry = splat4(setup.volume.reject_y) * cw;
    const Mask4 beyond = ((cx > rx) & splatMask4(1 << VertexWindow::kRejectShift)) |
                         ((cx < -rx) & splatMask4(2 << VertexWindow::kRejectShift)) |
                         ((cy > ry) & splatMask4(4 << VertexWindow::kRejectShift)) |
                         ((cy < -ry) & splatMask4(8 << VertexWindow::kRejectShift));
    // toWindow(): the same products and sums in the same order.
    const Lane4 inv_w = splat4(1.0) / cw;
    const Lane4 x = (cx * inv_w * half + half) * width;
    const Lane4 y = (cy * inv_w * half + half) * height;
    const Lane4 z = cz * inv_w * half + half;
    const Mask4 drawable =
        finite & inside & (cw > zero) & (abs4(x) < inf) & (abs4(y) < inf) & (abs4(z) < inf);
    const Mask4 flags = (finite & splatMask4(VertexWindow::kFinite)) |
                        (finite & inside & (splatMask4(VertexWindow::kInside) | beyond)) |
                        (drawable & splatMask4(VertexWindow::kDrawable));
    const Lane4 sx = snap4(x, scale, drawable);
    const Lane4 sy = snap4(y, scale, drawable);
    for (std::size_t k = 0; k < n; ++k) {
      VertexWindow& w = out[i + k];
      w.x = x[k];
      w.y = y[k];
      w.z = z[k];
      w.inv_w = inv_w[k];
      w.fixed = FixedVertex{static_cast<std::int64_t>(sx[k]) - setup.shift_x,
                            static_cast<std::int64_t>(sy[k]) - setup.shift_y};
      w.flags = static_cast<std::uint8_t>(flags[k]);
    }
  }
}

}  // namespace

namespace detail {
void setUpVertexWindowsBaseline(const TransformedVertex* verts, std::size_t count,
                                const WindowSetup& setup, VertexWindow* out) {
  setUpLanes(verts, count, setup, out);
}
__attribute__((target("avx2"))) void setUpVertexWindowsAvx2(const TransformedVertex* verts,
                                                            std::size_t count,
                                                            const WindowSetup& setup,
                                                            VertexWindow* out) {
  setUpLanes(verts, count, setup, out);
}
}  // namespace detail

VertexWindow vertexWindowDefinition(const glm::dvec4& c, const WindowSetup& setup) {
  VertexWindow w{};
  if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z) || !std::isfinite(c.w))
    return w;
  w.flags = VertexWindow::kFinite;
  const ClipVolume& v = setup.volume;
  // classifyTriangle()'s planes: near and far, then the guard band.
  if (!(std::fabs(c.z) <= c.w && std::fabs(c.x) <= v.guard_x * c.w &&
        std::fabs(c.y) <= v.guard_y * c.w))
    return w;
  w.flags |= VertexWindow::kInside;
  // Beyond which side of the reject band (a triangle with every vertex beyond one is dropped).
  const unsigned beyond = (c.x > v.reject_x * c.w ? 1u : 0u) | (c.x < -v.reject_x * c.w ? 2u : 0u) |
                          (c.y > v.reject_y * c.w ? 4u : 0u) | (c.y < -v.reject_y * c.w ? 8u : 0u);
  w.flags |= static_cast<std::uint8_t>(beyond << VertexWindow::kRejectShift);
  if (!(c.w > 0.0)) return w;
  const WindowVertex wv =
      toWindow(ClipVertex{c, glm::dvec3(0.0), glm::dvec4(0.0)}, setup.width, setup.height);
  if (!std::isfinite(wv.x) || !std::isfinite(wv.y) || !std::isfinite(wv.z)) return w;
  w.flags |= VertexWindow::kDrawable;
  w.x = wv.x;
  w.y = wv.y;
  w.z = wv.z;
  w.inv_w = wv.inv_w;
  w.fixed = snapVertexScaled(wv.x, wv.y, setup.snap_scale);
  w.fixed.x -= setup.shift_x;
  w.fixed.y -= setup.shift_y;
  return w;
}

// x86-64's baseline or AVX2 (no FMA), whichever the CPU has: the bits are the same either
// way (lanes.h); AVX2 does four lanes per instruction where SSE2 does two.
void setUpVertexWindows(const TransformedVertex* verts, std::size_t count, const WindowSetup& setup,
                        VertexWindow* out) {
  static const bool kAvx2 = __builtin_cpu_supports("avx2");
  if (kAvx2) {
    detail::setUpVertexWindowsAvx2(verts, count, setup, out);
  } else {
    detail::setUpVertexWindowsBaseline(verts, count, setup, out);
  }
}

}  // namespace rc::ref
