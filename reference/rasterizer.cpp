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

int clampToInt(std::int64_t v, int lo, int hi) {
  return static_cast<int>(std::clamp<std::int64_t>(v, lo, hi));
}

// Triangles at most this many pixels wide get their row spans by scanning (cheaper than
// three 64-bit divisions per row).
constexpr int kScanWidth = 16;

}  // namespace

double guardLimitPx(int subpixel_bits) {
  return std::ldexp(1.0, kFixedCoordinateBits - subpixel_bits);
}

FixedVertex snapVertex(double window_x, double window_y, int subpixel_bits) {
  return snapVertexScaled(window_x, window_y, std::ldexp(1.0, subpixel_bits));
}

std::int64_t snappedArea2(const FixedVertex& v0, const FixedVertex& v1, const FixedVertex& v2) {
  return (v1.x - v0.x) * (v2.y - v0.y) - (v2.x - v0.x) * (v1.y - v0.y);
}

bool TriangleCoverage::setup(const FixedVertex& v0, const FixedVertex& v1, const FixedVertex& v2,
                             int subpixel_bits, const PixelRect& clip) {
  const std::int64_t area2 = snappedArea2(v0, v1, v2);
  if (area2 == 0) return false;
  // Counter-clockwise order, so that the inside of every edge is E > 0.
  const FixedVertex v[3] = {v0, area2 > 0 ? v1 : v2, area2 > 0 ? v2 : v1};
  for (int i = 0; i < 3; ++i) {
    const FixedVertex& p = v[i];
    const FixedVertex& q = v[(i + 1) % 3];
    const std::int64_t A = p.y - q.y;  // inward normal (A, B)
    const std::int64_t B = q.x - p.x;
    const bool includes_ties = A > 0 || (A == 0 && B > 0);
    edges_[i].a = A * (std::int64_t{1} << subpixel_bits);
    edges_[i].b = B * (std::int64_t{1} << subpixel_bits);
    edges_[i].c = -A * p.x - B * p.y + (includes_ties ? 1 : 0);
  }
  // Pixel centres inside the snapped bounding box, within the clip rectangle.
  const std::int64_t min_x = std::min({v0.x, v1.x, v2.x});
  const std::int64_t max_x = std::max({v0.x, v1.x, v2.x});
  const std::int64_t min_y = std::min({v0.y, v1.y, v2.y});
  const std::int64_t max_y = std::max({v0.y, v1.y, v2.y});
  const std::int64_t one = std::int64_t{1} << subpixel_bits;
  col_begin_ = clampToInt(ceilDiv(min_x, one), clip.x0, clip.x1);
  col_end_ = clampToInt(floorDiv(max_x, one) + 1, clip.x0, clip.x1);
  row_begin_ = clampToInt(ceilDiv(min_y, one), clip.y0, clip.y1);
  row_end_ = clampToInt(floorDiv(max_y, one) + 1, clip.y0, clip.y1);
  return col_begin_ < col_end_ && row_begin_ < row_end_;
}

bool TriangleCoverage::covers(int px, int py) const {
  if (px < col_begin_ || px >= col_end_ || py < row_begin_ || py >= row_end_) return false;
  for (const Edge& e : edges_)
    if (!(e.a * px + e.b * py + e.c > 0)) return false;
  return true;
}

bool TriangleCoverage::rowSpan(int py, int& x_begin, int& x_end) const {
  return col_end_ - col_begin_ <= kScanWidth ? rowSpanByScan(py, x_begin, x_end)
                                             : rowSpanByDivision(py, x_begin, x_end);
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
  std::int64_t e[3];
  for (int i = 0; i < 3; ++i) e[i] = edges_[i].a * col_begin_ + edges_[i].b * py + edges_[i].c;
  int px = col_begin_;
  while (px < col_end_ && !(e[0] > 0 && e[1] > 0 && e[2] > 0)) {
    for (int i = 0; i < 3; ++i) e[i] += edges_[i].a;
    ++px;
  }
  if (px == col_end_) return false;
  x_begin = px;
  while (px < col_end_ && e[0] > 0 && e[1] > 0 && e[2] > 0) {
    for (int i = 0; i < 3; ++i) e[i] += edges_[i].a;
    ++px;
  }
  x_end = px;
  return true;
}

}  // namespace rc::ref
