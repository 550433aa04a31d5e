// The diamond-exit rule with a symbolic perturbation: see line_raster.h.
#include "reference/line_raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

namespace rc::ref {
namespace {

// 128 bits: products of two 64-bit snapped coordinates (a GCC and Clang extension).
__extension__ typedef __int128 Wide;

// c0 + c1 e + c2 e^2 for an infinitesimal e > 0.
struct Sym {
  std::int64_t c0 = 0;
  std::int64_t c1 = 0;
  std::int64_t c2 = 0;
};

Sym minus(std::int64_t k, const Sym& s) { return {k - s.c0, -s.c1, -s.c2}; }
Sym minus(const Sym& s, std::int64_t k) { return {s.c0 - k, s.c1, s.c2}; }

// Sign of a symbolic value: its first non-zero coefficient decides.
int sign(const Sym& s) {
  for (std::int64_t c : {s.c0, s.c1, s.c2})
    if (c != 0) return c > 0 ? 1 : -1;
  return 0;
}

// A bound on the segment's parameter t: num / den (den > 0), strict or not.
struct Bound {
  Sym num;
  std::int64_t den = 1;
  bool strict = false;
};

// Sign of a.num / a.den - b.num / b.den, exactly (cross products in 128 bits).
int compare(const Bound& a, const Bound& b) {
  const std::array<std::int64_t, 3> an = {a.num.c0, a.num.c1, a.num.c2};
  const std::array<std::int64_t, 3> bn = {b.num.c0, b.num.c1, b.num.c2};
  for (int k = 0; k < 3; ++k) {
    const Wide l = static_cast<Wide>(an[k]) * b.den;
    const Wide r = static_cast<Wide>(bn[k]) * a.den;
    if (l != r) return l < r ? -1 : 1;
  }
  return 0;
}

// The parameter interval [lower, upper] (each end strict or not) of the perturbed segment.
struct Interval {
  Bound lower{{0, 0, 0}, 1, false};  // t >= 0
  Bound upper{{1, 0, 0}, 1, false};  // t <= 1
  bool empty = false;

  void raiseLower(const Bound& b) {
    const int c = compare(b, lower);
    if (c > 0 || (c == 0 && b.strict)) lower = b;
  }
  void lowerUpper(const Bound& b) {
    const int c = compare(b, upper);
    if (c < 0 || (c == 0 && b.strict)) upper = b;
  }
  // lo < start + t d < hi, for the open slab (lo, hi) along one rotated axis.
  void clipSlab(const Sym& start, std::int64_t d, std::int64_t lo, std::int64_t hi) {
    if (d == 0) {
      if (!(sign(minus(start, lo)) > 0 && sign(minus(hi, start)) > 0)) empty = true;
      return;
    }
    // t > (lo - start) / d and t < (hi - start) / d for d > 0; the other way round for d < 0.
    const Sym from_lo = minus(lo, start);
    const Sym from_hi = minus(hi, start);
    if (d > 0) {
      raiseLower({from_lo, d, true});
      lowerUpper({from_hi, d, true});
    } else {
      raiseLower({{-from_hi.c0, -from_hi.c1, -from_hi.c2}, -d, true});
      lowerUpper({{-from_lo.c0, -from_lo.c1, -from_lo.c2}, -d, true});
    }
  }
  bool feasible() const {
    if (empty) return false;
    const int c = compare(lower, upper);
    return c < 0 || (c == 0 && !lower.strict && !upper.strict);
  }
};

// A perturbed endpoint p - (e, e^2) in u = x + y, v = x - y.
Sym perturbedU(const FixedVertex& p) { return {p.x + p.y, -1, -1}; }
Sym perturbedV(const FixedVertex& p) { return {p.x - p.y, -1, 1}; }

bool insideSlab(const Sym& s, std::int64_t lo, std::int64_t hi) {
  return sign(minus(s, lo)) > 0 && sign(minus(hi, s)) > 0;
}

}  // namespace

bool lineProducesFragment(const FixedVertex& a, const FixedVertex& b, std::int64_t cx,
                          std::int64_t cy, int subpixel_bits) {
  const std::int64_t h = std::int64_t{1} << (subpixel_bits - 1 < 0 ? 0 : subpixel_bits - 1);
  // subpixel_bits 0 has no half unit: the diamond's half-width is then 1/2 in units of 1 px,
  // so everything is doubled instead.
  const std::int64_t scale = subpixel_bits == 0 ? 2 : 1;
  const FixedVertex sa{a.x * scale, a.y * scale};
  const FixedVertex sb{b.x * scale, b.y * scale};
  const std::int64_t cu = (cx + cy) * scale;
  const std::int64_t cv = (cx - cy) * scale;
  // The exit rule: pb' inside the diamond produces nothing.
  if (insideSlab(perturbedU(sb), cu - h, cu + h) && insideSlab(perturbedV(sb), cv - h, cv + h))
    return false;
  Interval t;
  t.clipSlab(perturbedU(sa), (sb.x + sb.y) - (sa.x + sa.y), cu - h, cu + h);
  t.clipSlab(perturbedV(sa), (sb.x - sb.y) - (sa.x - sa.y), cv - h, cv + h);
  return t.feasible();
}

std::vector<LinePixel> rasterizeLine(const FixedVertex& a, const FixedVertex& b, int subpixel_bits,
                                     const PixelRect& clip) {
  std::vector<LinePixel> out;
  const double unit = std::ldexp(1.0, -subpixel_bits);
  const double ax = static_cast<double>(a.x) * unit, ay = static_cast<double>(a.y) * unit;
  const double bx = static_cast<double>(b.x) * unit, by = static_cast<double>(b.y) * unit;
  const bool x_major = std::abs(bx - ax) >= std::abs(by - ay);
  // Along the major axis every pixel between the endpoints (and one beyond); across it the
  // rows (columns) within one pixel of the line at that centre: the diamond has a radius
  // of half a pixel, so no other pixel can be met.
  const double lo = std::floor(std::min(x_major ? ax : ay, x_major ? bx : by)) - 1.0;
  const double hi = std::ceil(std::max(x_major ? ax : ay, x_major ? bx : by)) + 1.0;
  for (double m = lo; m <= hi; m += 1.0) {
    const double along = x_major ? bx - ax : by - ay;
    const double across0 = x_major ? ay : ax;
    const double across1 = x_major ? by : bx;
    const double start = x_major ? ax : ay;
    const double f = along == 0.0 ? 0.0 : std::clamp((m - start) / along, 0.0, 1.0);
    const double c = across0 + f * (across1 - across0);
    for (double n = std::floor(c) - 1.0; n <= std::ceil(c) + 1.0; n += 1.0) {
      const int px = static_cast<int>(x_major ? m : n);
      const int py = static_cast<int>(x_major ? n : m);
      if (px < clip.x0 || px >= clip.x1 || py < clip.y0 || py >= clip.y1) continue;
      const std::int64_t cx = static_cast<std::int64_t>(px) << subpixel_bits;
      const std::int64_t cy = static_cast<std::int64_t>(py) << subpixel_bits;
      if (lineProducesFragment(a, b, cx, cy, subpixel_bits)) out.push_back({px, py});
    }
  }
  std::sort(out.begin(), out.end(), [](const LinePixel& p, const LinePixel& q) {
    return p.y != q.y ? p.y < q.y : p.x < q.x;
  });
  out.erase(
      std::unique(out.begin(), out.end(),
                  [](const LinePixel& p, const LinePixel& q) { return p.x == q.x && p.y == q.y; }),
      out.end());
  return out;
}

double roundedLineWidth(double width) { return std::max(1.0, std::floor(width + 0.5)); }

bool halfLineWidth(double width) { return width > 1.0 && width - std::floor(width) == 0.5; }

std::vector<LinePixel> rasterizeWideLine(const FixedVertex& a, const FixedVertex& b, double width,
                                         int subpixel_bits, const PixelRect& clip) {
  const auto w = static_cast<int>(roundedLineWidth(width));
  if (w == 1) return rasterizeLine(a, b, subpixel_bits, clip);
  const bool x_major = std::llabs(b.x - a.x) >= std::llabs(b.y - a.y);
  // (w - 1) / 2 px in snapped units: exact, also for an even w (half a pixel) unless the
  // grid has no half unit (0 bits), where the offset is done in doubled units instead.
  const int bits = subpixel_bits == 0 ? 1 : subpixel_bits;
  const std::int64_t k = subpixel_bits == 0 ? 2 : 1;
  const std::int64_t shift = static_cast<std::int64_t>(w - 1) << (bits - 1);
  FixedVertex oa{a.x * k, a.y * k}, ob{b.x * k, b.y * k};
  (x_major ? oa.y : oa.x) -= shift;
  (x_major ? ob.y : ob.x) -= shift;
  // The replicated fragments reach w - 1 pixels past the offset segment's: rasterize it
  // unclipped in the minor direction by that much, then clip each fragment.
  PixelRect wide = clip;
  (x_major ? wide.y0 : wide.x0) -= w - 1;
  std::vector<LinePixel> out;
  for (const LinePixel& p : rasterizeLine(oa, ob, bits, wide)) {
    for (int i = 0; i < w; ++i) {
      const LinePixel q = x_major ? LinePixel{p.x, p.y + i} : LinePixel{p.x + i, p.y};
      if (q.x >= clip.x0 && q.x < clip.x1 && q.y >= clip.y0 && q.y < clip.y1) out.push_back(q);
    }
  }
  std::sort(out.begin(), out.end(), [](const LinePixel& p, const LinePixel& q) {
    return p.y != q.y ? p.y < q.y : p.x < q.x;
  });
  return out;
}

std::vector<LinePixel> rasterizePoint(const FixedVertex& center, double size, int subpixel_bits,
                                      const PixelRect& clip) {
  std::vector<LinePixel> out;
  if (!(size > 0.0) || !std::isfinite(size)) return out;
  // Compared in units of 2^-bits px: a centre c is covered iff low <= c < high on both axes,
  // low = center - size / 2 (in double: exact for sizes on the grid, and the comparison of a
  // centre, an integer, with it is then exact too).
  const double half = size * std::ldexp(1.0, subpixel_bits) / 2.0;
  const double unit = std::ldexp(1.0, subpixel_bits);
  auto range = [&](std::int64_t c, int lo_clip, int hi_clip) {
    const double low = static_cast<double>(c) - half, high = static_cast<double>(c) + half;
    const int first = std::max(lo_clip, static_cast<int>(std::max(-1e9, std::ceil(low / unit))));
    int last = static_cast<int>(std::min(1e9, std::ceil(high / unit))) - 1;  // centre < high
    last = std::min(last, hi_clip - 1);
    return std::pair<int, int>{first, last};
  };
  const auto [x0, x1] = range(center.x, clip.x0, clip.x1);
  const auto [y0, y1] = range(center.y, clip.y0, clip.y1);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) out.push_back({x, y});
  return out;
}

}  // namespace rc::ref
