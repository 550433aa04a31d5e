// Uncertainty channels: see uncertainty.h.
#include "reference/uncertainty.h"

#include <algorithm>
#include <cmath>

#include "reference/fragment_ops.h"

namespace rc::ref {

float DepthGapTracker::gapSteps(std::size_t index, DepthFormat format) const {
  const double gap = slots_[index].gap;
  if (!std::isfinite(gap)) return std::numeric_limits<float>::infinity();
  return static_cast<float>(gap * depthStepsPerUnit(format));
}

void DepthGapTracker::writeSteps(DepthFormat format, float* out) const {
  const double steps = depthStepsPerUnit(format);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const double gap = slots_[i].gap;
    out[i] = std::isfinite(gap) ? static_cast<float>(gap * steps)
                                : std::numeric_limits<float>::infinity();
  }
}

double polygonArea2(const WindowVertex* polygon, int count) {
  double area2 = 0.0;
  for (int i = 1; i + 1 < count; ++i) {
    const double e1x = polygon[i].x - polygon[0].x;
    const double e1y = polygon[i].y - polygon[0].y;
    const double e2x = polygon[i + 1].x - polygon[0].x;
    const double e2y = polygon[i + 1].y - polygon[0].y;
    area2 += e1x * e2y - e2x * e1y;
  }
  return area2;
}

double polygonPerimeter(const WindowVertex* polygon, int count) {
  double p = 0.0;
  for (int i = 0; i < count; ++i) {
    const WindowVertex& a = polygon[i];
    const WindowVertex& b = polygon[(i + 1) % count];
    p += std::hypot(b.x - a.x, b.y - a.y);
  }
  return p;
}

bool cullCouldFlip(const WindowVertex* polygon, int count) {
  constexpr double d = kSnapDisagreementPx;
  return std::fabs(polygonArea2(polygon, count)) <=
         2.0 * d * polygonPerimeter(polygon, count) + 4.0 * d * d;
}

namespace {

// Distance from (px, py) to the segment a-b.
double segmentDistance(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax;
  const double dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0);
  return std::hypot(px - (ax + t * dx), py - (ay + t * dy));
}

// Pixel indices whose centre (i + 0.5) lies in [lo, hi], clamped to [begin, end).
bool centreRange(double lo, double hi, int begin, int end, int& first, int& last_excl) {
  const double f = std::ceil(lo - 0.5);
  const double l = std::floor(hi - 0.5);
  if (!(f <= l)) return false;
  first = static_cast<int>(std::max<double>(f, begin));
  last_excl = static_cast<int>(std::min<double>(l + 1.0, end));
  return first < last_excl;
}

void addSegment(const WindowVertex& a, const WindowVertex& b, const PixelRect& clip, int width,
                int height, float* edge_dist) {
  int row_first = 0;
  int row_end = 0;
  if (!centreRange(std::min(a.y, b.y) - 1.0, std::max(a.y, b.y) + 1.0, clip.y0, clip.y1, row_first,
                   row_end))
    return;
  for (int py = row_first; py < row_end; ++py) {
    const double cy = py + 0.5;
    // The part of the segment within one pixel of this row's centre line bounds the
    // centres that can be closer than 1.
    double t0 = 0.0;
    double t1 = 1.0;
    if (b.y != a.y) {
      t0 = (cy - 1.0 - a.y) / (b.y - a.y);
      t1 = (cy + 1.0 - a.y) / (b.y - a.y);
      if (t0 > t1) std::swap(t0, t1);
      t0 = std::max(t0, 0.0);
      t1 = std::min(t1, 1.0);
      if (t0 > t1) continue;
    }
    const double xa = a.x + t0 * (b.x - a.x);
    const double xb = a.x + t1 * (b.x - a.x);
    int col_first = 0;
    int col_end = 0;
    if (!centreRange(std::min(xa, xb) - 1.0, std::max(xa, xb) + 1.0, clip.x0, clip.x1, col_first,
                     col_end))
      continue;
    float* row = edge_dist + static_cast<std::size_t>(height - 1 - py) * width;
    for (int px = col_first; px < col_end; ++px) {
      const double d = segmentDistance(px + 0.5, cy, a.x, a.y, b.x, b.y);
      if (d < row[px]) row[px] = static_cast<float>(d);
    }
  }
}

}  // namespace

void addEdgeDistances(const WindowVertex* polygon, int count, const PixelRect& clip, int width,
                      int height, float* edge_dist) {
  for (int i = 0; i < count; ++i)
    addSegment(polygon[i], polygon[(i + 1) % count], clip, width, height, edge_dist);
}

}  // namespace rc::ref
