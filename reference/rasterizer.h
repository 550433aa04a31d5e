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

#include <algorithm>
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
struct FixedVertex {  // plain data (arrays of them live on the stack per triangle)
  std::int64_t x;
  std::int64_t y;
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
inline std::int64_t snappedArea2(const FixedVertex& v0, const FixedVertex& v1,
                                 const FixedVertex& v2) {
  return (v1.x - v0.x) * (v2.y - v0.y) - (v2.x - v0.x) * (v1.y - v0.y);
}

// The pixels whose centres lie inside the snapped bounding box of v0, v1, v2 (subpixel
// units, `subpixel_bits` fractional bits), within `clip`: [col_begin, col_end) x
// [row_begin, row_end), empty when either range is. TriangleCoverage's box, and the rows
// the renderer prefetches (prefetch.h).
struct PixelBox {
  int col_begin;
  int col_end;
  int row_begin;
  int row_end;
  bool empty() const { return !(col_begin < col_end && row_begin < row_end); }
};
inline PixelBox snappedPixelBox(const FixedVertex& v0, const FixedVertex& v1, const FixedVertex& v2,
                                int subpixel_bits, const PixelRect& clip) {
  // floor(n / 2^bits) is the arithmetic shift n >> bits and ceil is -((-n) >> bits) (C++20
  // defines >> on negative values as flooring); |n| < 2^61, so -n cannot overflow.
  const std::int64_t min_x = std::min(v0.x, std::min(v1.x, v2.x));
  const std::int64_t max_x = std::max(v0.x, std::max(v1.x, v2.x));
  const std::int64_t min_y = std::min(v0.y, std::min(v1.y, v2.y));
  const std::int64_t max_y = std::max(v0.y, std::max(v1.y, v2.y));
  auto clamp = [](std::int64_t n, int lo, int hi) {
    return static_cast<int>(n < lo ? lo : n > hi ? hi : n);
  };
  return PixelBox{clamp(-((-min_x) >> subpixel_bits), clip.x0, clip.x1),
                  clamp((max_x >> subpixel_bits) + 1, clip.x0, clip.x1),
                  clamp(-((-min_y) >> subpixel_bits), clip.y0, clip.y1),
                  clamp((max_y >> subpixel_bits) + 1, clip.y0, clip.y1)};
}

class TriangleCoverage {
 public:
  // Prepares the edge functions of a triangle with non-zero snapped area (either winding)
  // restricted to `clip`. Returns false when it covers nothing (zero area or outside);
  // the object is then not to be used.
  bool setup(const FixedVertex& v0, const FixedVertex& v1, const FixedVertex& v2, int subpixel_bits,
             const PixelRect& clip);

  // Calls fn(py, x_begin, x_end) for every row with covered pixels, bottom to top;
  // [x_begin, x_end) are the covered pixels of that row (a row's covered set is one run).
  // Narrow triangles step the edge functions incrementally (integers: exactly the values
  // covers() computes), wide ones divide per row (rowSpanByDivision()).
  template <class SpanFn>
  void forEachSpan(SpanFn&& fn) const {
    if (col_end_ - col_begin_ > kScanWidth) {
      for (int py = row_begin_; py < row_end_; ++py) {
        int lo = 0;
        int hi = 0;
        if (rowSpanByDivision(py, lo, hi)) fn(py, lo, hi);
      }
      return;
    }
    const Edge& e0 = edges_[0];
    const Edge& e1 = edges_[1];
    const Edge& e2 = edges_[2];
    // Edge values at (col_begin_, py), advanced by b per row.
    std::int64_t r0 = e0.a * col_begin_ + e0.b * row_begin_ + e0.c;
    std::int64_t r1 = e1.a * col_begin_ + e1.b * row_begin_ + e1.c;
    std::int64_t r2 = e2.a * col_begin_ + e2.b * row_begin_ + e2.c;
    for (int py = row_begin_; py < row_end_; ++py, r0 += e0.b, r1 += e1.b, r2 += e2.b) {
      int lo = 0;
      int hi = 0;
      if (scanRow(r0, r1, r2, lo, hi)) fn(py, lo, hi);
    }
  }

  // Whether pixel (px, py) is covered: the per-pixel definition that the span methods
  // compute faster (tests hold them equal).
  bool covers(int px, int py) const;

  // Span of one row: exact integer division (wide triangles), or a scan from col_begin_
  // (narrow ones; forEachSpan steps the same scan from row to row).
  bool rowSpanByDivision(int py, int& x_begin, int& x_end) const;
  bool rowSpanByScan(int py, int& x_begin, int& x_end) const;

 private:
  // The covered run of a row whose three edge values at (col_begin_, row) are f0..f2,
  // stepping them by a along the row.
  bool scanRow(std::int64_t f0, std::int64_t f1, std::int64_t f2, int& x_begin, int& x_end) const {
    const std::int64_t a0 = edges_[0].a;
    const std::int64_t a1 = edges_[1].a;
    const std::int64_t a2 = edges_[2].a;
    int px = col_begin_;
    while (px < col_end_ && !(f0 > 0 && f1 > 0 && f2 > 0)) {
      f0 += a0;
      f1 += a1;
      f2 += a2;
      ++px;
    }
    x_begin = px;
    while (px < col_end_ && f0 > 0 && f1 > 0 && f2 > 0) {
      f0 += a0;
      f1 += a1;
      f2 += a2;
      ++px;
    }
    x_end = px;
    return x_end > x_begin;
  }

  // Triangles at most this many pixels wide are scanned (cheaper than three 64-bit
  // divisions per row).
  static constexpr int kScanWidth = 16;

  // E(px, py) = a * px + b * py + c, covered iff E > 0 for all three edges; the tie-break
  // is folded into c (+1 for included edges, so E >= 0 becomes E + 1 > 0). Plain data:
  // setup() sets every field.
  struct Edge {
    std::int64_t a;
    std::int64_t b;
    std::int64_t c;
  };
  Edge edges_[3];
  int row_begin_;
  int row_end_;
  int col_begin_;
  int col_end_;
};

inline bool TriangleCoverage::setup(const FixedVertex& v0, const FixedVertex& v1,
                                    const FixedVertex& v2, int subpixel_bits,
                                    const PixelRect& clip) {
  const std::int64_t area2 = snappedArea2(v0, v1, v2);
  if (area2 == 0) return false;
  // Counter-clockwise order, so that the inside of every edge is E > 0.
  const FixedVertex v[3] = {v0, area2 > 0 ? v1 : v2, area2 > 0 ? v2 : v1};
  for (int i = 0; i < 3; ++i) {
    const FixedVertex& p = v[i];
    const FixedVertex& q = v[i == 2 ? 0 : i + 1];
    const std::int64_t A = p.y - q.y;  // inward normal (A, B)
    const std::int64_t B = q.x - p.x;
    const bool includes_ties = A > 0 || (A == 0 && B > 0);
    edges_[i].a = A * (std::int64_t{1} << subpixel_bits);
    edges_[i].b = B * (std::int64_t{1} << subpixel_bits);
    edges_[i].c = -A * p.x - B * p.y + (includes_ties ? 1 : 0);
  }
  const PixelBox box = snappedPixelBox(v0, v1, v2, subpixel_bits, clip);
  col_begin_ = box.col_begin;
  col_end_ = box.col_end;
  row_begin_ = box.row_begin;
  row_end_ = box.row_end;
  return !box.empty();
}

}  // namespace rc::ref
