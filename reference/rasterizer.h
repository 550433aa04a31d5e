// Rasterizer: coverage only. Window coordinates are snapped to a fixed-point grid and
// each triangle's three integer edge functions decide which pixel centres it covers,
// with llvmpipe's tie-break rule for centres exactly on an edge (docs/reference.md has
// the Mesa source facts and the probe that confirm it):
//
//   a centre on an edge is covered iff the edge's inward normal (nx, ny) has nx > 0, or
//   nx == 0 and ny > 0: left edges and, in GL window coordinates (y up), bottom edges.
//
// Shared edges are thus covered exactly once (never twice, never a gap). It does not
// clip, cull, interpolate, shade or test depth; the renderer does.
#pragma once

#include <cstdint>

#include "reference/rounding.h"

namespace rc::ref {

inline constexpr int kMaxSubpixelBits = 12;

// Fixed-point budget: snapped coordinates stay within +/- 2^29 units (of 2^-bits px),
// so every edge function value fits in int64 with headroom (|E| < 2^61). The guard band
// (clipper.h) keeps window coordinates within guardLimitPx(bits) to honour it.
inline constexpr int kFixedCoordinateBits = 29;
double guardLimitPx(int subpixel_bits);

// Half-open pixel rectangle in GL window coordinates (y up): the viewport, or one pixel
// when tracing.
struct PixelRect {
  int x0 = 0;
  int y0 = 0;
  int x1 = 0;
  int y1 = 0;
};

// A snapped vertex: (window coordinate - 0.5) * 2^bits rounded to nearest, ties to even
// (llvmpipe subtracts its pixel_offset 0.5 and converts with cvtps2dq). Pixel (px, py)'s
// centre is then exactly (px << bits, py << bits).
struct FixedVertex {
  std::int64_t x = 0;
  std::int64_t y = 0;
};
FixedVertex snapVertex(double window_x, double window_y, int subpixel_bits);
// The same with scale = 2^subpixel_bits computed once by the caller (the product by a
// power of two is exact, so the results are identical).
inline FixedVertex snapVertexScaled(double window_x, double window_y, double scale) {
  return FixedVertex{static_cast<std::int64_t>(roundHalfEven((window_x - 0.5) * scale)),
                     static_cast<std::int64_t>(roundHalfEven((window_y - 0.5) * scale))};
}

// Twice the signed area of a snapped triangle, in units^2 (> 0: counter-clockwise in GL
// window coordinates). Exact.
std::int64_t snappedArea2(const FixedVertex& v0, const FixedVertex& v1, const FixedVertex& v2);

class TriangleCoverage {
 public:
  // Prepares the edge functions of a triangle with non-zero snapped area (either winding)
  // restricted to `clip`. Returns false when it covers nothing (zero area or outside).
  bool setup(const FixedVertex& v0, const FixedVertex& v1, const FixedVertex& v2, int subpixel_bits,
             const PixelRect& clip);

  // Calls fn(py, x_begin, x_end) for every row with covered pixels, bottom to top;
  // [x_begin, x_end) are the covered pixels of that row (a row's covered set is one run).
  template <class SpanFn>
  void forEachSpan(SpanFn&& fn) const {
    for (int py = row_begin_; py < row_end_; ++py) {
      int lo = 0;
      int hi = 0;
      if (rowSpan(py, lo, hi)) fn(py, lo, hi);
    }
  }

  // Whether pixel (px, py) is covered: the per-pixel definition that rowSpan() computes
  // faster (tests hold them equal).
  bool covers(int px, int py) const;

  // Span of one row: exact integer division for wide triangles, a scan for narrow ones.
  bool rowSpan(int py, int& x_begin, int& x_end) const;
  bool rowSpanByDivision(int py, int& x_begin, int& x_end) const;
  bool rowSpanByScan(int py, int& x_begin, int& x_end) const;

 private:
  // E(px, py) = a * px + b * py + c, covered iff E > 0 for all three edges; the tie-break
  // is folded into c (+1 for included edges, so E >= 0 becomes E + 1 > 0).
  struct Edge {
    std::int64_t a = 0;
    std::int64_t b = 0;
    std::int64_t c = 0;
  };
  Edge edges_[3];
  int row_begin_ = 0;
  int row_end_ = 0;
  int col_begin_ = 0;
  int col_end_ = 0;
};

}  // namespace rc::ref
