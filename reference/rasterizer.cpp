// Rasterizer: see rasterizer.h.
#include "reference/rasterizer.h"

#include <algorithm>
#include <cmath>

#include "reference/rounding.h"

namespace rc::ref {
namespace {

// Floor and ceiling of n / d for d > 0 (C++ division truncates towards zero).
std::int64_t floorDiv(std::int64_t n, std::int64_t d) {
  std::int64_t q = n / d;
  if ((n % d != 0) && (n < 0)) --q;
  return q;
}
std::int64_t ceilDiv(std::int64_t n, std::int64_t d) {
  std::int64_t q = n / d;
  if ((n % d != 0) && (n > 0)) ++q;
  return q;
}

}  // namespace

double guardLimitPx(int subpixel_bits) {
  return std::ldexp(1.0, kFixedCoordinateBits - subpixel_bits);
}

FixedVertex snapVertex(double window_x, double window_y, int subpixel_bits) {
  return snapVertexScaled(window_x, window_y, std::ldexp(1.0, subpixel_bits));
}

bool TriangleCoverage::covers(int px, int py) const {
  if (px < col_begin_ || px >= col_end_ || py < row_begin_ || py >= row_end_) return false;
  for (const Edge& e : edges_)
    if (!(e.a * px + e.b * py + e.c > 0)) return false;
  return true;
}

bool TriangleCoverage::rowSpanByDivision(int py, int& x_begin, int& x_end) const {
  std::int64_t lo = col_begin_;
  std::int64_t hi = col_end_;  // exclusive
  for (const Edge& e : edges_) {
    const std::int64_t k = e.b * py + e.c;  // E = a * px + k > 0
    if (e.a > 0) {
      lo = std::max(lo, floorDiv(-k, e.a) + 1);
    } else if (e.a < 0) {
      hi = std::min(hi, ceilDiv(k, -e.a));
    } else if (k <= 0) {
      return false;
    }
  }
  if (lo >= hi) return false;
  x_begin = static_cast<int>(lo);
  x_end = static_cast<int>(hi);
  return true;
}

bool TriangleCoverage::rowSpanByScan(int py, int& x_begin, int& x_end) const {
  return scanRow(edges_[0].a * col_begin_ + edges_[0].b * py + edges_[0].c,
                 edges_[1].a * col_begin_ + edges_[1].b * py + edges_[1].c,
                 edges_[2].a * col_begin_ + edges_[2].b * py + edges_[2].c, x_begin, x_end);
}

}  // namespace rc::ref
