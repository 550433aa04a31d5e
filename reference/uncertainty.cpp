// Uncertainty channels: see uncertainty.h.
#include "reference/uncertainty.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "reference/fragment_ops.h"
#include "reference/lanes.h"

#include <immintrin.h>

namespace rc::ref {

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

bool cullCouldFlip(const WindowVertex* polygon, int count, double extra_px) {
  const double d = kSnapDisagreementPx + extra_px;
  return std::fabs(polygonArea2(polygon, count)) <=
         2.0 * d * polygonPerimeter(polygon, count) + 4.0 * d * d;
}

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// floor(x) without a libm call (SSE2 has no rounding instruction): truncation through
// int64 is exact for |x| < 2^52 and is corrected downwards for negative fractions. Only
// the sign of a zero result can differ from std::floor, which the callers never see.
inline double floorFast(double x) {
  if (!(std::fabs(x) < 4503599627370496.0)) return std::floor(x);
  const double t = static_cast<double>(static_cast<std::int64_t>(x));
  return t > x ? t - 1.0 : t;
}
inline double ceilFast(double x) { return -floorFast(-x); }

// Pixel indices whose centre (i + 0.5) lies in [lo, hi], clamped to [begin, end).
[[gnu::always_inline]] inline bool centreRange(double lo, double hi, int begin, int end, int& first,
                                               int& last_excl) {
  const double f = ceilFast(lo - 0.5);
  const double l = floorFast(hi - 0.5);
  if (!(f <= l)) return false;
  first = static_cast<int>(std::max<double>(f, begin));
  last_excl = static_cast<int>(std::min<double>(l + 1.0, end));
  return first < last_excl;
}

// A segment's end point (the x, y of a WindowVertex).
struct Point {
  double x;
  double y;
};

// Lowers row[px] to the distance from each listed pixel centre to the segment a-b (in
// [first, last) of the row at window y = cy), when that is smaller:
//   t = clamp(((p - a) . d) / |d|^2, 0, 1), distance = hypot(p - (a + t d)).
// The hypot call is skipped where it cannot lower the value: with q = p - (a + t d),
// fl(qx^2 + qy^2) is within 2^-51 (relative) of |q|^2 and hypot is within an ulp of |q|,
// so fl(qx^2 + qy^2) >= cur^2 (1 + 2^-40) means hypot(q) > cur and no change (cur is a
// float, so cur^2 is exact in double). Pixels are visited in any superset of the band
// within one pixel of the segment: a pixel farther than 1 keeps its value (<= 1).
void lowerRow(float* row, int first, int last, double cy, const Point& a, const Point& b,
              double reach) {
  const double dx = b.x - a.x;
  const double dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  const bool finite_len2 = std::isfinite(len2);
  const double py = cy;
  for (int px = first; px < last; ++px) {
    const double cx = px + 0.5;
    double t = 0.0;
    if (len2 > 0.0) {
      // t = clamp(num / len2, 0, 1) without the division where the clamp decides: for a
      // finite len2 > 0, num >= len2 gives a quotient >= 1 (rounding is monotone) and
      // num <= 0 one <= 0 (t = -0 for num = -0, which moves no end point: a.x + -0 * dx
      // and a.x + 0 * dx differ at most in the sign of a zero, and cx, py are never 0).
      const double num = (cx - a.x) * dx + (py - a.y) * dy;
      if (!finite_len2) {
        t = std::clamp(num / len2, 0.0, 1.0);
      } else if (num >= len2) {
        t = 1.0;
      } else if (!(num <= 0.0)) {
        t = num / len2;  // in (0, 1] (the clamp keeps it) or NaN (the clamp returns it)
      }
    }
    const double qx = cx - (a.x + t * dx);
    const double qy = py - (a.y + t * dy);
    const double cur = row[px];
    const double limit = cur + reach;  // == cur without reach: the same test, bit for bit
    const double sum = qx * qx + qy * qy;
    if (sum >= limit * limit * (1.0 + 0x1p-40)) continue;
    // What hypot would store, decided without calling it where an interval around it
    // decides: for a normal sum, s = sqrt(sum) is within 2^-51 (relative) of |q| (two
    // roundings in the sum, one in the root; an underflowed square is below 2^-74 of it)
    // and hypot within an ulp (2^-52) of |q|, so hypot(q) lies in [s (1 - 2^-48), s (1 +
    // 2^-48)] with room to spare. Subtracting reach, max and the float conversion are
    // monotone, so when both ends give the same outcome (no change, or the same stored
    // float) hypot's value gives it too. Otherwise (about 2^-24 of the visits, and NaN or
    // extreme sums) hypot itself.
    if (sum >= 0x1p-1000 && sum < kInfinity) {
      const double root = std::sqrt(sum);
      const double lo = root * (1.0 - 0x1p-48) - reach;
      if (!(lo < cur)) continue;  // hypot(q) - reach >= lo >= cur: no change
      const double hi = root * (1.0 + 0x1p-48) - reach;
      const auto stored = static_cast<float>(std::max(lo, 0.0));
      if (hi < cur && stored == static_cast<float>(std::max(hi, 0.0))) {
        row[px] = stored;
        continue;
      }
    }
    const double d = std::hypot(qx, qy) - reach;
    if (d < cur) row[px] = static_cast<float>(std::max(d, 0.0));
  }
}

// Lane4 values stay inside addSegment() (everything it calls on them is inlined): -Wpsabi's
// note on passing 32-byte vectors without AVX does not apply (for the rest of the file: GCC
// also gives it at the end of the translation unit).
#pragma GCC diagnostic ignored "-Wpsabi"

// std::max(x, 0.0) per lane: (x < 0) ? 0 : x (NaN and -0 stay as they are).
[[gnu::always_inline]] inline Lane4 maxWithZero4(Lane4 x) {
  return x < splat4(0.0) ? splat4(0.0) : x;
}

// lowerRow() four pixel centres at a time (a segment without a finite len2 > 0 goes to
// lowerRow() itself): in each lane the scalar code's operations on the same operands ((py - a.y) *
// dy is the same product in every lane, computed once per row), its branches as per-lane selects; a
// lane that needs hypot gets the scalar code's hypot step on that lane's qx, qy and cur. So every
// pixel ends with the bits lowerRow() gives. Lanes past `last` are read and written back unchanged
// where the row has them (`width` floats), so that four pixels load and store as one vector.
class SegmentLanes {
 public:
  SegmentLanes(const Point& a, const Point& b, double reach)
      : a_(a),
        b_(b),
        dx_(b.x - a.x),
        dy_(b.y - a.y),
        len2_(dx_ * dx_ + dy_ * dy_),
        reach_(reach),
        vdx_(splat4(dx_)),
        vdy_(splat4(dy_)),
        vlen2_(splat4(len2_)),
        ax_(splat4(a.x)),
        ay_(splat4(a.y)),
        vreach_(splat4(reach)) {}
  using Float4 = float __attribute__((vector_size(16)));

  // Whether the vector path applies (else rc::ref::lowerRow() does the segment).
  bool vectorised() const { return len2_ > 0.0 && std::isfinite(len2_); }
  // (cy - a.y) * dy: the part of the projection that is the same along a row.
  [[gnu::always_inline]] Lane4 alongY(double cy) const { return splat4((cy - a_.y) * dy_); }

  [[gnu::always_inline]] void lowerRow(float* row, int first, int last, int width,
                                       double cy) const {
    if (!vectorised()) {
      rc::ref::lowerRow(row, first, last, cy, a_, b_, reach_);
      return;
    }
    const Lane4 along_y = alongY(cy);
    const Lane4 vcy = splat4(cy);
    for (int px = first; px < last; px += 4) {
      const int n = std::min(4, last - px);
      const bool whole = px + 4 <= width;  // four floats of the row to load and store
      Float4 cur_f = {1.0f, 1.0f, 1.0f, 1.0f};
      if (whole) {
        __builtin_memcpy(&cur_f, row + px, sizeof cur_f);
      } else {
        for (int k = 0; k < n; ++k) cur_f[k] = row[px + k];
      }
      const Float4 out = lower4(cur_f, px, n, vcy, along_y);
      if (whole) {
        __builtin_memcpy(row + px, &out, sizeof out);
      } else {
        for (int k = 0; k < n; ++k) row[px + k] = out[k];
      }
    }
  }

  // The pixel centres px .. px + 3 of the row at vcy (along_y = alongY(cy)) whose values are
  // cur_f: each lowered where the segment is closer, as rc::ref::lowerRow() lowers it; lanes
  // n .. 3 returned unchanged. Only where vectorised().
  [[gnu::always_inline]] Float4 lower4(Float4 cur_f, int px, int n, Lane4 vcy,
                                       Lane4 along_y) const {
    const double c0 = px + 0.5;
    const Lane4 cx = {c0, c0 + 1.0, c0 + 2.0, c0 + 3.0};  // exact: small integers + 0.5
    const Lane4 num = (cx - ax_) * vdx_ + along_y;
    const Lane4 t = num >= vlen2_ ? splat4(1.0) : num <= splat4(0.0) ? splat4(0.0) : num / vlen2_;
    const Lane4 qx = cx - (ax_ + t * vdx_);
    const Lane4 qy = vcy - (ay_ + t * vdy_);
    const Lane4 cur = __builtin_convertvector(cur_f, Lane4);
    const Lane4 limit = cur + vreach_;
    const Lane4 sum = qx * qx + qy * qy;
    // Lanes the scalar code does not skip at its first test (NaN sums included).
    const Mask4 in_range = Mask4{0, 1, 2, 3} < Mask4{n, n, n, n};
    const Mask4 open = in_range & ~(sum >= limit * limit * splat4(1.0 + 0x1p-40));
    if ((open[0] | open[1] | open[2] | open[3]) == 0) return cur_f;
    const Mask4 interval = (sum >= splat4(0x1p-1000)) & (sum < splat4(kInfinity));
    const Lane4 root = sqrt4(sum);
    const Lane4 lo = root * splat4(1.0 - 0x1p-48) - vreach_;
    const Lane4 hi = root * splat4(1.0 + 0x1p-48) - vreach_;
    const Mask4 lowers = lo < cur;
    const Float4 stored = __builtin_convertvector(maxWithZero4(lo), Float4);
    const Float4 stored_hi = __builtin_convertvector(maxWithZero4(hi), Float4);
    const Mask4 same = __builtin_convertvector(stored == stored_hi, Mask4);
    const Mask4 decided = open & interval & lowers & (hi < cur) & same;
    // Lanes that need hypot: open, and the interval decides neither "no change" nor
    // the stored value.
    const Mask4 slow = open & ~(interval & (~lowers | decided));
    const auto decided_f = __builtin_convertvector(decided, Float4Mask);
    Float4 out = decided_f ? stored : cur_f;
    if ((slow[0] | slow[1] | slow[2] | slow[3]) == 0) return out;
    for (int k = 0; k < n; ++k) {
      if (!slow[k]) continue;
      const double d = std::hypot(qx[k], qy[k]) - reach_;
      if (d < cur[k]) out[k] = static_cast<float>(std::max(d, 0.0));
    }
    return out;
  }

 private:
  using Float4Mask = std::int32_t __attribute__((vector_size(16)));
  Point a_;
  Point b_;
  double dx_;
  double dy_;
  double len2_;
  double reach_;
  Lane4 vdx_;
  Lane4 vdy_;
  Lane4 vlen2_;
  Lane4 ax_;
  Lane4 ay_;
  Lane4 vreach_;
};

// Segments this short across (px, in x or y) visit the columns of their bounding box,
// widened by the band, on every row: a superset of the per-row band that costs no
// division per row (visiting more centres changes nothing, lowerRow()'s comment).
constexpr double kBoxSegmentPx = 4.0;

// Compiled twice, for x86-64's baseline and for AVX2 (no FMA), picked at load time; the
// bits are the same either way.
__attribute__((target_clones("avx2", "default"))) void addSegment(const Point& a, const Point& b,
                                                                  const PixelRect& clip, int width,
                                                                  int height, float* edge_dist,
                                                                  double reach) {
  // Centres farther than 1 + reach from the segment keep their value (<= 1).
  const double band = 1.0 + reach;
  int row_first = 0;
  int row_end = 0;
  if (!centreRange(std::min(a.y, b.y) - band, std::max(a.y, b.y) + band, clip.y0, clip.y1,
                   row_first, row_end))
    return;
  const SegmentLanes lanes(a, b, reach);
  auto rowOf = [&](int py) {
    return edge_dist + static_cast<std::size_t>(height - 1 - py) * width;
  };
  const bool finite = std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) &&
                      std::isfinite(b.y) && std::isfinite(band);
  if (finite && std::min(std::fabs(b.x - a.x), std::fabs(b.y - a.y)) <= kBoxSegmentPx) {
    int col_first = 0;
    int col_end = 0;
    if (!centreRange(std::min(a.x, b.x) - band, std::max(a.x, b.x) + band, clip.x0, clip.x1,
                     col_first, col_end))
      return;
    for (int py = row_first; py < row_end; ++py)
      lanes.lowerRow(rowOf(py), col_first, col_end, width, py + 0.5);
    return;
  }
  for (int py = row_first; py < row_end; ++py) {
    const double cy = py + 0.5;
    // The part of the segment within one pixel of this row's centre line bounds the
    // centres that can be closer than 1.
    double t0 = 0.0;
    double t1 = 1.0;
    if (b.y != a.y) {
      t0 = (cy - band - a.y) / (b.y - a.y);
      t1 = (cy + band - a.y) / (b.y - a.y);
      if (t0 > t1) std::swap(t0, t1);
      t0 = std::max(t0, 0.0);
      t1 = std::min(t1, 1.0);
      if (t0 > t1) continue;
    }
    const double xa = a.x + t0 * (b.x - a.x);
    const double xb = a.x + t1 * (b.x - a.x);
    int col_first = 0;
    int col_end = 0;
    if (!centreRange(std::min(xa, xb) - band, std::max(xa, xb) + band, clip.x0, clip.x1, col_first,
                     col_end))
      continue;
    lanes.lowerRow(rowOf(py), col_first, col_end, width, cy);
  }
}

// Triangles at most this many pixels across (in x and in y), with every edge's reach at
// most kSmallTriangleReachPx, are lowered in one pass over their bounding box widened by the
// band (EdgeDistanceBatch): each group of four centres loaded once for the three edges.
constexpr double kSmallTrianglePx = 4.0;
constexpr double kSmallTriangleReachPx = 1.0;

// The centres a small triangle's pass visits: its bounding box widened by the band of its
// widest-reaching edge, within clip (empty() when there are none).
[[gnu::always_inline]] inline PixelBox smallTriangleBox(const Point& a, const Point& b,
                                                        const Point& c, const double* reach,
                                                        const PixelRect& clip) {
  const double band = 1.0 + std::max({reach[0], reach[1], reach[2]});
  PixelBox box{0, 0, 0, 0};
  if (!centreRange(std::min({a.y, b.y, c.y}) - band, std::max({a.y, b.y, c.y}) + band, clip.y0,
                   clip.y1, box.row_begin, box.row_end) ||
      !centreRange(std::min({a.x, b.x, c.x}) - band, std::max({a.x, b.x, c.x}) + band, clip.x0,
                   clip.x1, box.col_begin, box.col_end))
    return PixelBox{0, 0, 0, 0};
  return box;
}

// The three edges of a small triangle (a -> b -> c -> a, each with its reach) lowered over
// the triangle's bounding box widened by the band: a superset of each edge's own visits
// (addSegment()), and visiting more centres changes nothing (lowerRow()), so each pixel
// ends as addSegment() of the three edges leaves it, whatever the order. Every edge has a
// finite, non-zero length (EdgeDistanceBatch::add() checks). Built like addSegment().
__attribute__((target_clones("avx2", "default"))) void addSmallTriangle(
    const Point& a, const Point& b, const Point& c, const double* reach, const PixelRect& clip,
    int width, int height, float* edge_dist) {
  const PixelBox box = smallTriangleBox(a, b, c, reach, clip);
  if (box.empty()) return;
  const SegmentLanes ab(a, b, reach[0]);
  const SegmentLanes bc(b, c, reach[1]);
  const SegmentLanes ca(c, a, reach[2]);
  for (int py = box.row_begin; py < box.row_end; ++py) {
    const double cy = py + 0.5;
    float* row = edge_dist + static_cast<std::size_t>(height - 1 - py) * width;
    const Lane4 vcy = splat4(cy);
    const Lane4 along_ab = ab.alongY(cy);
    const Lane4 along_bc = bc.alongY(cy);
    const Lane4 along_ca = ca.alongY(cy);
    for (int px = box.col_begin; px < box.col_end; px += 4) {
      const int n = std::min(4, box.col_end - px);
      const bool whole = px + 4 <= width;  // four floats of the row to load and store
      SegmentLanes::Float4 cur = {1.0f, 1.0f, 1.0f, 1.0f};
      if (whole) {
        __builtin_memcpy(&cur, row + px, sizeof cur);
      } else {
        for (int k = 0; k < n; ++k) cur[k] = row[px + k];
      }
      cur = ab.lower4(cur, px, n, vcy, along_ab);
      cur = bc.lower4(cur, px, n, vcy, along_bc);
      cur = ca.lower4(cur, px, n, vcy, along_ca);
      if (whole) {
        __builtin_memcpy(row + px, &cur, sizeof cur);
      } else {
        for (int k = 0; k < n; ++k) row[px + k] = cur[k];
      }
    }
  }
}

// The small-triangle pass eight centres at a time, on processors with AVX-512 (F, DQ, VL:
// compares into masks and back): two rows of four. The narrow pass above gives each row's
// four centres a vector of their own, and a triangle of 2 px with its band of 1 px spans
// four or five rows of four or five centres, so most groups are one per row; here a group
// takes two rows and the triangle's groups, divisions and square roots are about halved.
// In each lane the operations of SegmentLanes::lower4() on the same operands (the
// projection's row part, (cy - a.y) * dy, per half), so each pixel ends with the bits the
// narrow pass and lowerRow() give (EdgeDist tests compare both passes with the definition).
using Lane8w = double __attribute__((vector_size(64)));
using Mask8w = std::int64_t __attribute__((vector_size(64)));
using Float8 = float __attribute__((vector_size(32)));
using Float8Mask = std::int32_t __attribute__((vector_size(32)));
using Float4w = float __attribute__((vector_size(16)));

#define RC_WIDE_TARGET __attribute__((target("avx512f,avx512dq,avx512vl")))
#define RC_WIDE_INLINE __attribute__((always_inline, target("avx512f,avx512dq,avx512vl")))

RC_WIDE_INLINE inline Lane8w splat8(double v) { return Lane8w{v, v, v, v, v, v, v, v}; }
RC_WIDE_INLINE inline Lane8w halves8(double lo, double hi) {
  return Lane8w{lo, lo, lo, lo, hi, hi, hi, hi};
}
// maxWithZero4() in eight lanes.
RC_WIDE_INLINE inline Lane8w maxWithZero8(Lane8w x) { return x < splat8(0.0) ? splat8(0.0) : x; }

class SegmentLanes8 {
 public:
  RC_WIDE_TARGET SegmentLanes8(const Point& a, const Point& b, double reach)
      : ay_(a.y),
        dy_(b.y - a.y),
        reach_(reach),
        vdx_(splat8(b.x - a.x)),
        vdy_(splat8(dy_)),
        vlen2_(splat8((b.x - a.x) * (b.x - a.x) + dy_ * dy_)),  // SegmentLanes' len2_
        ax_(splat8(a.x)),
        ay8_(splat8(a.y)),
        vreach_(splat8(reach)) {}
  // (cy - a.y) * dy of the two rows, each in its half.
  RC_WIDE_INLINE Lane8w alongY(double cy0, double cy1) const {
    return halves8((cy0 - ay_) * dy_, (cy1 - ay_) * dy_);
  }
  // lower4() of eight centres (cx, vcy) whose values are cur_f; lanes outside in_range
  // returned unchanged.
  RC_WIDE_INLINE Float8 lower8(Float8 cur_f, Lane8w cx, Lane8w vcy, Lane8w along_y,
                               Mask8w in_range) const {
    const Lane8w num = (cx - ax_) * vdx_ + along_y;
    const Lane8w t = num >= vlen2_ ? splat8(1.0) : num <= splat8(0.0) ? splat8(0.0) : num / vlen2_;
    const Lane8w qx = cx - (ax_ + t * vdx_);
    const Lane8w qy = vcy - (ay8_ + t * vdy_);
    const Lane8w cur = __builtin_convertvector(cur_f, Lane8w);
    const Lane8w limit = cur + vreach_;
    const Lane8w sum = qx * qx + qy * qy;
    const Mask8w open = in_range & ~(sum >= limit * limit * splat8(1.0 + 0x1p-40));
    if (!anyLane(open)) return cur_f;
    const Mask8w interval = (sum >= splat8(0x1p-1000)) & (sum < splat8(kInfinity));
    const Lane8w root =
        reinterpret_cast<Lane8w>(_mm512_maskz_sqrt_pd(0xFF, reinterpret_cast<__m512d>(sum)));
    const Lane8w lo = root * splat8(1.0 - 0x1p-48) - vreach_;
    const Lane8w hi = root * splat8(1.0 + 0x1p-48) - vreach_;
    const Mask8w lowers = lo < cur;
    const Float8 stored = __builtin_convertvector(maxWithZero8(lo), Float8);
    const Float8 stored_hi = __builtin_convertvector(maxWithZero8(hi), Float8);
    const Mask8w same = __builtin_convertvector(stored == stored_hi, Mask8w);
    const Mask8w decided = open & interval & lowers & (hi < cur) & same;
    const Mask8w slow = open & ~(interval & (~lowers | decided));
    const auto decided_f = __builtin_convertvector(decided, Float8Mask);
    Float8 out = decided_f ? stored : cur_f;
    if (!anyLane(slow)) return out;
    for (int k = 0; k < 8; ++k) {
      if (!slow[k]) continue;
      const double d = std::hypot(qx[k], qy[k]) - reach_;
      if (d < cur[k]) out[k] = static_cast<float>(std::max(d, 0.0));
    }
    return out;
  }

 private:
  RC_WIDE_INLINE static bool anyLane(Mask8w m) {
    return _mm512_test_epi64_mask(reinterpret_cast<__m512i>(m), reinterpret_cast<__m512i>(m)) != 0;
  }
  double ay_;
  double dy_;
  double reach_;
  Lane8w vdx_;
  Lane8w vdy_;
  Lane8w vlen2_;
  Lane8w ax_;
  Lane8w ay8_;
  Lane8w vreach_;
};

// addSmallTriangle() with SegmentLanes8: the same box, two rows per group.
RC_WIDE_TARGET void addSmallTriangleWide(const Point& a, const Point& b, const Point& c,
                                         const double* reach, const PixelRect& clip, int width,
                                         int height, float* edge_dist) {
  const PixelBox box = smallTriangleBox(a, b, c, reach, clip);
  if (box.empty()) return;
  const SegmentLanes8 ab(a, b, reach[0]);
  const SegmentLanes8 bc(b, c, reach[1]);
  const SegmentLanes8 ca(c, a, reach[2]);
  const Mask8w lane = {0, 1, 2, 3, 0, 1, 2, 3};
  const Mask8w upper = {0, 0, 0, 0, -1, -1, -1, -1};
  for (int py = box.row_begin; py < box.row_end; py += 2) {
    const bool two = py + 1 < box.row_end;  // else the upper half is out of range
    const double cy0 = py + 0.5;
    const double cy1 = py + 1.5;
    // Rows are stored top down: row py + 1 is `width` floats before row py.
    float* row0 = edge_dist + static_cast<std::size_t>(height - 1 - py) * width;
    float* row1 = two ? row0 - width : row0;
    const Lane8w vcy = halves8(cy0, cy1);
    const Lane8w along_ab = ab.alongY(cy0, cy1);
    const Lane8w along_bc = bc.alongY(cy0, cy1);
    const Lane8w along_ca = ca.alongY(cy0, cy1);
    const Mask8w rows = two ? ~Mask8w{} : ~upper;
    for (int px = box.col_begin; px < box.col_end; px += 4) {
      const int n = std::min(4, box.col_end - px);
      const bool whole = px + 4 <= width;
      Float4w lo = {1.0f, 1.0f, 1.0f, 1.0f};
      Float4w hi = lo;
      if (whole) {
        __builtin_memcpy(&lo, row0 + px, sizeof lo);
        if (two) __builtin_memcpy(&hi, row1 + px, sizeof hi);
      } else {
        for (int k = 0; k < n; ++k) {
          lo[k] = row0[px + k];
          if (two) hi[k] = row1[px + k];
        }
      }
      Float8 cur = __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
      const double c0 = px + 0.5;
      const Lane8w cx = {c0, c0 + 1.0, c0 + 2.0, c0 + 3.0, c0, c0 + 1.0, c0 + 2.0, c0 + 3.0};
      const Mask8w in_range = rows & (lane < Mask8w{n, n, n, n, n, n, n, n});
      cur = ab.lower8(cur, cx, vcy, along_ab, in_range);
      cur = bc.lower8(cur, cx, vcy, along_bc, in_range);
      cur = ca.lower8(cur, cx, vcy, along_ca, in_range);
      lo = __builtin_shufflevector(cur, cur, 0, 1, 2, 3);
      hi = __builtin_shufflevector(cur, cur, 4, 5, 6, 7);
      if (whole) {
        __builtin_memcpy(row0 + px, &lo, sizeof lo);
        if (two) __builtin_memcpy(row1 + px, &hi, sizeof hi);
      } else {
        for (int k = 0; k < n; ++k) {
          row0[px + k] = lo[k];
          if (two) row1[px + k] = hi[k];
        }
      }
    }
  }
}
#undef RC_WIDE_TARGET
#undef RC_WIDE_INLINE

}  // namespace

void addEdgeDistances(const WindowVertex* polygon, int count, const PixelRect& clip, int width,
                      int height, float* edge_dist, const double* reach_px) {
  for (int i = 0; i < count; ++i) {
    const int j = (i + 1) % count;
    const double reach = reach_px ? std::max(reach_px[i], reach_px[j]) : 0.0;
    addSegment(Point{polygon[i].x, polygon[i].y}, Point{polygon[j].x, polygon[j].y}, clip, width,
               height, edge_dist, reach);
  }
}

void EdgeDistanceBatch::add(const WindowVertex* polygon, int count, const double* reach_px) {
  if (count == 3) {
    SmallTriangle t{};
    bool small = true;
    for (int i = 0; i < 3 && small; ++i) {
      const int j = i == 2 ? 0 : i + 1;
      const double dx = polygon[j].x - polygon[i].x;
      const double dy = polygon[j].y - polygon[i].y;
      const double len2 = dx * dx + dy * dy;
      t.x[i] = polygon[i].x;
      t.y[i] = polygon[i].y;
      t.reach[i] = std::max(reach_px[i], reach_px[j]);
      // The vector path of every edge (a finite, non-zero length), a small box (finite
      // coordinates: their differences are finite), a narrow band.
      small = len2 > 0.0 && std::isfinite(len2) && std::fabs(dx) <= kSmallTrianglePx &&
              std::fabs(dy) <= kSmallTrianglePx && t.reach[i] <= kSmallTriangleReachPx &&
              std::isfinite(polygon[i].x) && std::isfinite(polygon[i].y);
    }
    if (small) {
      const double low = std::min({t.y[0], t.y[1], t.y[2]});
      t.key = static_cast<std::int32_t>(low > 0.0 ? std::min(low, 65536.0) : 0.0);
      triangles_.push_back(t);
      return;
    }
  }
  for (int i = 0; i < count; ++i) {
    const int j = (i + 1) % count;
    const WindowVertex& a = polygon[i];
    const WindowVertex& b = polygon[j];
    // Any key gives the same result; the lower row (clamped, NaN to 0) gives locality.
    const double low = std::min(a.y, b.y);
    const double row = low > 0.0 ? std::min(low, 65536.0) : 0.0;
    segments_.push_back(Segment{a.x, a.y, b.x, b.y, std::max(reach_px[i], reach_px[j]),
                                static_cast<std::int32_t>(row)});
  }
}

bool EdgeDistanceBatch::wideLanesAvailable() {
  static const bool kWide = __builtin_cpu_supports("avx512f") &&
                            __builtin_cpu_supports("avx512dq") &&
                            __builtin_cpu_supports("avx512vl");
  return kWide;
}

void EdgeDistanceBatch::apply(const PixelRect& clip, int width, int height, float* edge_dist) {
  // Counting sort by key (keys in [0, 65536]).
  int max_key = 0;
  for (const Segment& s : segments_) max_key = std::max(max_key, s.key);
  starts_.assign(static_cast<std::size_t>(max_key) + 2, 0);
  for (const Segment& s : segments_) ++starts_[static_cast<std::size_t>(s.key) + 1];
  for (std::size_t k = 1; k < starts_.size(); ++k) starts_[k] += starts_[k - 1];
  sorted_.resize(segments_.size());
  for (const Segment& s : segments_) sorted_[starts_[static_cast<std::size_t>(s.key)]++] = s;
  for (const Segment& s : sorted_)
    addSegment(Point{s.ax, s.ay}, Point{s.bx, s.by}, clip, width, height, edge_dist, s.reach);
  // The small triangles, by the same counting sort.
  max_key = 0;
  for (const SmallTriangle& t : triangles_) max_key = std::max(max_key, t.key);
  starts_.assign(static_cast<std::size_t>(max_key) + 2, 0);
  for (const SmallTriangle& t : triangles_) ++starts_[static_cast<std::size_t>(t.key) + 1];
  for (std::size_t k = 1; k < starts_.size(); ++k) starts_[k] += starts_[k - 1];
  sorted_triangles_.resize(triangles_.size());
  for (const SmallTriangle& t : triangles_)
    sorted_triangles_[starts_[static_cast<std::size_t>(t.key)]++] = t;
  auto* const add_triangle =
      wide_lanes_ && wideLanesAvailable() ? addSmallTriangleWide : addSmallTriangle;
  for (const SmallTriangle& t : sorted_triangles_)
    add_triangle(Point{t.x[0], t.y[0]}, Point{t.x[1], t.y[1]}, Point{t.x[2], t.y[2]}, t.reach, clip,
                 width, height, edge_dist);
  clear();
}

double planeSetupError(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2) {
  constexpr double u = 0x1p-24;  // float32 unit roundoff
  // The area and the gradient are the same whichever vertex is the reference (their
  // float32 errors are not): computed once, from v0.
  const double area = (v1.x - v0.x) * (v2.y - v0.y) - (v2.x - v0.x) * (v1.y - v0.y);
  const double gx = ((v1.z - v0.z) * (v2.y - v0.y) - (v2.z - v0.z) * (v1.y - v0.y)) / area;
  const double gy = ((v1.x - v0.x) * (v2.z - v0.z) - (v2.x - v0.x) * (v1.z - v0.z)) / area;
  const double inv_area = 1.0 / std::fabs(area);
  const double agx = std::fabs(gx);
  const double agy = std::fabs(gy);
  if (!std::isfinite(inv_area) || !std::isfinite(agx) || !std::isfinite(agy))
    return std::numeric_limits<double>::infinity();
  const WindowVertex* v[3] = {&v0, &v1, &v2};
  double worst = 0.0;
  double slack = 0.0;
  for (int k = 0; k < 3; ++k) {  // the implementation's reference vertex a
    const WindowVertex& a = *v[k];
    const WindowVertex& b = *v[k == 2 ? 0 : k + 1];
    const WindowVertex& c = *v[k == 0 ? 2 : k - 1];
    const double ux = b.x - a.x;
    const double uy = b.y - a.y;
    const double uz = b.z - a.z;
    const double vx = c.x - a.x;
    const double vy = c.y - a.y;
    const double vz = c.z - a.z;
    // Each product of two rounded differences carries 3 roundings, each sum and the
    // quotient one more: |d gx| <= u (3 (|uz vy| + |vz uy|) + 3 |gx| (|ux vy| + |vx uy|))
    // / |area| + 3 u |gx| (the numerator's error, the area's error times gx, the rest).
    const double cross = std::fabs(ux * vy) + std::fabs(vx * uy);
    const double ex =
        3.0 * u * ((std::fabs(uz * vy) + std::fabs(vz * uy) + agx * cross) * inv_area + agx);
    const double ey =
        3.0 * u * ((std::fabs(ux * vz) + std::fabs(vx * uz) + agy * cross) * inv_area + agy);
    // At (x, y): the gradient's error times the distance from a, and the evaluation's own
    // roundings (two products, two sums). Convex in (x, y): over the triangle it is
    // largest at a vertex (at a itself, u |z_a|); 1 px further in x and y adds `step`.
    const double fx = ex + 2.0 * u * agx;
    const double fy = ey + 2.0 * u * agy;
    const double za = u * std::fabs(a.z);
    worst = std::max({worst, za + fx * std::fabs(ux) + fy * std::fabs(uy),
                      za + fx * std::fabs(vx) + fy * std::fabs(vy)});
    slack = std::max(slack, fx + fy);
  }
  const double e = worst + slack;
  return std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
}

namespace {

// Whether triangle (a, b, c) covers a pixel centre, its edges moved out by `margin` px: row by
// row, the centres between the triangle's crossings of the row's centre line.
bool coversPixelCentre(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c,
                       double margin) {
  const WindowVertex* v[3] = {&a, &b, &c};
  const double y_lo = std::min({a.y, b.y, c.y}) - margin;
  const double y_hi = std::max({a.y, b.y, c.y}) + margin;
  for (double row = std::ceil(y_lo - 0.5); row + 0.5 <= y_hi; row += 1.0) {
    const double yc = row + 0.5;
    double x_lo = std::numeric_limits<double>::infinity();
    double x_hi = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const WindowVertex& p = *v[k];
      const WindowVertex& q = *v[(k + 1) % 3];
      const double lo = std::min(p.y, q.y) - margin;
      const double hi = std::max(p.y, q.y) + margin;
      if (yc < lo || yc > hi) continue;
      const double x = p.y == q.y
                           ? p.x
                           : p.x + (std::clamp(yc, std::min(p.y, q.y), std::max(p.y, q.y)) - p.y) *
                                       (q.x - p.x) / (q.y - p.y);
      const double other = p.y == q.y ? q.x : x;
      x_lo = std::min({x_lo, x, other});
      x_hi = std::max({x_hi, x, other});
    }
    if (x_lo > x_hi) continue;
    if (std::ceil(x_lo - margin - 0.5) <= std::floor(x_hi + margin - 0.5)) return true;
  }
  return false;
}

}  // namespace

double sideClipSetupError(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                          double width, double height) {
  auto inside = [&](const WindowVertex& v) {
    return v.x >= 0.0 && v.x <= width && v.y >= 0.0 && v.y <= height;
  };
  if (inside(v0) && inside(v1) && inside(v2)) return 0.0;
  // Sutherland-Hodgman against the four sides; window z is affine on the screen, so a new
  // vertex's depth is the edge's, interpolated in window space.
  std::vector<WindowVertex> poly = {v0, v1, v2};
  const struct {
    bool x;
    double bound;
    bool keep_above;
  } sides[4] = {
      {true, 0.0, true}, {true, width, false}, {false, 0.0, true}, {false, height, false}};
  for (const auto& side : sides) {
    std::vector<WindowVertex> out;
    const std::size_t n = poly.size();
    for (std::size_t k = 0; k < n; ++k) {
      const WindowVertex& p = poly[k];
      const WindowVertex& q = poly[(k + 1) % n];
      const double dp = (side.x ? p.x : p.y) - side.bound;
      const double dq = (side.x ? q.x : q.y) - side.bound;
      const bool p_in = side.keep_above ? dp >= 0.0 : dp <= 0.0;
      const bool q_in = side.keep_above ? dq >= 0.0 : dq <= 0.0;
      if (p_in) out.push_back(p);
      if (p_in != q_in) {
        const double t = dp / (dp - dq);
        WindowVertex m = p;
        m.x = p.x + t * (q.x - p.x);
        m.y = p.y + t * (q.y - p.y);
        m.z = p.z + t * (q.z - p.z);
        out.push_back(m);
      }
    }
    poly = std::move(out);
    if (poly.size() < 3) return 0.0;
  }
  const std::size_t n = poly.size();
  double worst = 0.0;
  for (std::size_t s = 0; s < n; ++s) {
    for (std::size_t j = 1; j + 1 < n; ++j) {
      const WindowVertex& a = poly[s];
      const WindowVertex& b = poly[(s + j) % n];
      const WindowVertex& c = poly[(s + j + 1) % n];
      const double area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
      if (!(std::fabs(area) > 0.0) || !coversPixelCentre(a, b, c, 0.01)) continue;
      const double e = planeSetupError(a, b, c);
      if (std::isfinite(e)) worst = std::max(worst, e);
    }
  }
  return worst;
}

}  // namespace rc::ref
