// The diamond-exit rule (reference/line_raster.h): analytic cases, the properties GL draws
// on it (a strip's segments share no fragment and leave no gap; an x-major segment has one
// fragment per column), and agreement with an independent oracle that perturbs the
// endpoints by a concrete tiny e in long double instead of symbolically.
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "reference/line_raster.h"

namespace rc::ref {
namespace {

constexpr int kBits = 4;  // a coarse grid: many endpoints exactly on diamond borders
constexpr std::int64_t kUnit = std::int64_t{1} << kBits;
const PixelRect kClip{-64, -64, 64, 64};

FixedVertex at(double x, double y) {  // pixel units, pixel centres at integers
  return {static_cast<std::int64_t>(std::llround(x * kUnit)),
          static_cast<std::int64_t>(std::llround(y * kUnit))};
}

std::set<std::pair<int, int>> pixels(const FixedVertex& a, const FixedVertex& b) {
  std::set<std::pair<int, int>> out;
  for (const LinePixel& p : rasterizeLine(a, b, kBits, kClip)) out.insert({p.x, p.y});
  return out;
}

// The oracle: the open diamond |x - cx| + |y - cy| < 1/2 against the segment with both
// endpoints moved by -(e, e^2), e = 1e-7 px, in long double; a point-in-diamond test on the
// moved end, and the segment's meeting with the diamond by clipping it against the two
// rotated slabs |u - cu| < 1/2, |v - cv| < 1/2. The grid's closest non-touching distances
// (1/16 px over lines of tens of pixels: ~1e-4 px) are far above e.
bool oracle(const FixedVertex& a, const FixedVertex& b, int px, int py) {
  using L = long double;
  const L e = 1e-7L, e2 = e * e;
  const L ax = static_cast<L>(a.x) / kUnit - e, ay = static_cast<L>(a.y) / kUnit - e2;
  const L bx = static_cast<L>(b.x) / kUnit - e, by = static_cast<L>(b.y) / kUnit - e2;
  auto inside = [&](L x, L y) { return std::fabs(x - px) + std::fabs(y - py) < 0.5L; };
  if (inside(bx, by)) return false;
  L t0 = 0, t1 = 1;
  for (int axis = 0; axis < 2; ++axis) {
    const L s = axis == 0 ? ax + ay : ax - ay;
    const L d = axis == 0 ? (bx + by) - (ax + ay) : (bx - by) - (ax - ay);
    const L c = axis == 0 ? L(px + py) : L(px - py);
    if (d == 0) {
      if (!(std::fabs(s - c) < 0.5L)) return false;
      continue;
    }
    L lo = (c - 0.5L - s) / d, hi = (c + 0.5L - s) / d;
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  return t0 < t1;
}

TEST(LineRaster, AHorizontalSegmentThroughCentresLeavesItsLastPixel) {
  EXPECT_EQ(pixels(at(0, 0), at(4, 0)),
            (std::set<std::pair<int, int>>{{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
  EXPECT_EQ(pixels(at(4, 0), at(0, 0)),
            (std::set<std::pair<int, int>>{{4, 0}, {3, 0}, {2, 0}, {1, 0}}));
  EXPECT_EQ(pixels(at(0, 0), at(0, 3)), (std::set<std::pair<int, int>>{{0, 0}, {0, 1}, {0, 2}}));
  EXPECT_TRUE(pixels(at(2, 2), at(2, 2)).empty()) << "a zero-length segment draws nothing";
  EXPECT_TRUE(pixels(at(2, 2), at(2.25, 2)).empty()) << "begins and ends in one diamond";
}

TEST(LineRaster, AgreesWithAConcretelyPerturbedOracle) {
  std::mt19937 rng(20261308);
  // Endpoints on a quarter-pixel grid: on diamond corners, borders and centres often.
  std::uniform_int_distribution<int> coord(-40, 40);
  int mismatches = 0, fragments = 0;
  for (int n = 0; n < 3000; ++n) {
    const FixedVertex a{coord(rng) * (kUnit / 4), coord(rng) * (kUnit / 4)};
    const FixedVertex b{coord(rng) * (kUnit / 4), coord(rng) * (kUnit / 4)};
    const std::set<std::pair<int, int>> got = pixels(a, b);
    fragments += static_cast<int>(got.size());
    for (int py = -12; py <= 12; ++py)
      for (int px = -12; px <= 12; ++px)
        if (got.contains({px, py}) != oracle(a, b, px, py)) ++mismatches;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(fragments, 3000 * 5);
}

// Consecutive segments of a strip: no pixel twice, none lost (the collinear strip draws
// what the whole segment draws), as the exit rule promises for joined segments.
TEST(LineRaster, AStripsSegmentsShareNoFragment) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::int64_t> coord(-24, 24);
  for (int n = 0; n < 500; ++n) {
    const FixedVertex a{coord(rng) * 4, coord(rng) * 4};
    const FixedVertex c{coord(rng) * 4, coord(rng) * 4};
    // b the midpoint of a -> c, when it lies on the grid.
    const FixedVertex b{a.x + (c.x - a.x) / 2, a.y + (c.y - a.y) / 2};
    if ((c.x - a.x) % 2 != 0 || (c.y - a.y) % 2 != 0) continue;
    const auto first = pixels(a, b), second = pixels(b, c), whole = pixels(a, c);
    for (const auto& p : first) EXPECT_FALSE(second.contains(p)) << n;
    std::set<std::pair<int, int>> both = first;
    both.insert(second.begin(), second.end());
    EXPECT_EQ(both, whole) << n;
  }
}

TEST(LineRaster, AnXMajorSegmentHasOneFragmentPerColumn) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::int64_t> coord(-30 * kUnit, 30 * kUnit);
  for (int n = 0; n < 2000; ++n) {
    const FixedVertex a{coord(rng), coord(rng)};
    const FixedVertex b{coord(rng), coord(rng)};
    if (std::llabs(b.x - a.x) < std::llabs(b.y - a.y)) continue;
    std::map<int, int> per_column;
    for (const auto& [x, y] : pixels(a, b)) ++per_column[x];
    for (const auto& [x, k] : per_column) EXPECT_EQ(k, 1) << "column " << x << " of case " << n;
    // Columns contiguous: no gap along the segment.
    if (!per_column.empty()) {
      EXPECT_EQ(per_column.rbegin()->first - per_column.begin()->first + 1,
                static_cast<int>(per_column.size()));
    }
  }
}

std::set<std::pair<int, int>> widePixels(const FixedVertex& a, const FixedVertex& b, double w) {
  std::set<std::pair<int, int>> out;
  for (const LinePixel& p : rasterizeWideLine(a, b, w, kBits, kClip)) out.insert({p.x, p.y});
  return out;
}

// GL's column rule: a width-3 horizontal segment through centres is three rows, centred;
// a width-2 one is offset half a pixel down, so its rows are the one below and its own;
// widths round to the nearest integer, 0.4 counting as 1; a y-major segment widens in x.
TEST(LineRaster, WideLinesAreColumnsOfRoundedWidth) {
  std::set<std::pair<int, int>> three, two;
  for (int x = 0; x < 4; ++x)
    for (int dy : {-1, 0, 1}) three.insert({x, dy});
  EXPECT_EQ(widePixels(at(0, 0), at(4, 0), 3.0), three);
  EXPECT_EQ(widePixels(at(0, 0), at(4, 0), 2.6), three);
  for (int x = 0; x < 4; ++x)
    for (int dy : {-1, 0}) two.insert({x, dy});
  EXPECT_EQ(widePixels(at(0, 0), at(4, 0), 2.0), two);
  EXPECT_EQ(widePixels(at(0, 0), at(4, 0), 0.4), pixels(at(0, 0), at(4, 0)));
  std::set<std::pair<int, int>> vertical;
  for (int y = 0; y < 3; ++y)
    for (int dx : {-1, 0, 1}) vertical.insert({dx, y});
  EXPECT_EQ(widePixels(at(0, 0), at(0, 3), 3.0), vertical);
  // Every column of a slanted x-major wide line holds exactly w fragments, contiguous.
  const auto slanted = widePixels(at(-7.3, 2.1), at(9.6, -3.4), 4.0);
  std::map<int, std::vector<int>> rows;
  for (const auto& [x, y] : slanted) rows[x].push_back(y);
  for (const auto& [x, ys] : rows) {
    ASSERT_EQ(ys.size(), 4u) << x;
    EXPECT_EQ(ys.back() - ys.front(), 3) << x;
  }
}

std::set<std::pair<int, int>> pointPixels(double x, double y, double size) {
  std::set<std::pair<int, int>> out;
  for (const LinePixel& p : rasterizePoint(at(x, y), size, kBits, kClip)) out.insert({p.x, p.y});
  return out;
}

// Points: the centres in the square of side `size`, the left and bottom borders included.
TEST(LineRaster, PointsAreSquaresOfTheirSize) {
  EXPECT_EQ(pointPixels(2, 3, 1), (std::set<std::pair<int, int>>{{2, 3}}));
  // Centred on a pixel corner (half-way between centres): the square [1.5, 2.5) holds the
  // centre on its left and bottom borders only.
  EXPECT_EQ(pointPixels(1.5, 1.5, 1), (std::set<std::pair<int, int>>{{1, 1}}));
  EXPECT_EQ(pointPixels(2, 2, 2), (std::set<std::pair<int, int>>{{1, 1}, {2, 1}, {1, 2}, {2, 2}}));
  EXPECT_EQ(pointPixels(2, 2, 3).size(), 9u);
  EXPECT_TRUE(pointPixels(2, 2, 0).empty());
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::int64_t> coord(-20 * kUnit, 20 * kUnit);
  for (int n = 0; n < 500; ++n) {
    const FixedVertex c{coord(rng), coord(rng)};
    for (int size = 1; size <= 6; ++size) {
      const auto got = rasterizePoint(c, size, kBits, kClip);
      EXPECT_EQ(got.size(), static_cast<std::size_t>(size * size)) << n << " size " << size;
      for (const LinePixel& p : got) {  // every centre within the square, half-open
        const double dx = static_cast<double>((std::int64_t{p.x} << kBits) - c.x) / kUnit;
        const double dy = static_cast<double>((std::int64_t{p.y} << kBits) - c.y) / kUnit;
        EXPECT_TRUE(dx >= -size / 2.0 && dx < size / 2.0 && dy >= -size / 2.0 && dy < size / 2.0);
      }
    }
  }
}

}  // namespace
}  // namespace rc::ref
