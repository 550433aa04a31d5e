// Coverage stage: snapping, llvmpipe's tie-break rule (patterns measured on Mesa 22.3.6
// llvmpipe, see docs/reference.md), exact span computation vs an independent oracle,
// and watertightness of shared edges.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "reference/prefetch.h"
#include "reference/rasterizer.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc::ref {
namespace {

__extension__ typedef __int128 Int128;  // exact oracle arithmetic (GCC/Clang builtin)

struct Tri2 {
  glm::dvec2 v[3];
};

// Independent statement of the rule: snap with libm's nearbyint, orient the triangle,
// a centre strictly inside every edge is covered; on an edge it is covered iff that
// edge's inward normal points right, or straight up (GL window coordinates, y up).
bool oracleCovers(const Tri2& t, int px, int py, int bits) {
  Int128 X[3];
  Int128 Y[3];
  for (int i = 0; i < 3; ++i) {
    X[i] = static_cast<Int128>(std::nearbyint((t.v[i].x - 0.5) * std::ldexp(1.0, bits)));
    Y[i] = static_cast<Int128>(std::nearbyint((t.v[i].y - 0.5) * std::ldexp(1.0, bits)));
  }
  const Int128 area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  if (area == 0) return false;
  const int o = area > 0 ? 1 : -1;
  const Int128 PX = static_cast<Int128>(px) << bits;
  const Int128 PY = static_cast<Int128>(py) << bits;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const Int128 ex = X[j] - X[i];
    const Int128 ey = Y[j] - Y[i];
    const Int128 side = o * (ex * (PY - Y[i]) - ey * (PX - X[i]));
    if (side > 0) continue;
    if (side < 0) return false;
    const Int128 nx = -o * ey;  // inward normal o * (-ey, ex)
    const Int128 ny = o * ex;
    if (!(nx > 0 || (nx == 0 && ny > 0))) return false;
  }
  return true;
}

TriangleCoverage setupCoverage(const Tri2& t, int bits, const PixelRect& clip, bool& ok) {
  TriangleCoverage c;
  ok = c.setup(snapVertex(t.v[0].x, t.v[0].y, bits), snapVertex(t.v[1].x, t.v[1].y, bits),
               snapVertex(t.v[2].x, t.v[2].y, bits), bits, clip);
  return c;
}

TEST(Snapping, RoundsHalfToEvenRelativeToPixelCentres) {
  // (x - 0.5) * 256: 3.5 + 1/512 -> 768.5 -> 768 (even); 3.5 + 3/512 -> 769.5 -> 770.
  EXPECT_EQ(snapVertex(3.5 + 1.0 / 512, 0.5, 8).x, 768);
  EXPECT_EQ(snapVertex(3.5 + 3.0 / 512, 0.5, 8).x, 770);
  EXPECT_EQ(snapVertex(3.5 - 1.0 / 512, 0.5, 8).x, 768);
  EXPECT_EQ(snapVertex(0.5 - 1.0 / 512, 0.5, 8).x, 0);   // -0.5 -> 0 (even)
  EXPECT_EQ(snapVertex(0.5 - 3.0 / 512, 0.5, 8).x, -2);  // -1.5 -> -2
  EXPECT_EQ(snapVertex(0.5, 7.25, 2).y, 27);
  EXPECT_EQ(snapVertex(3.7, 0.5, 0).x, 3);  // 0 bits: vertices snap to pixel centres
  EXPECT_EQ(snapVertex(4.0, 0.5, 0).x, 4);  // 3.5 -> 4 (even)
  EXPECT_EQ(snapVertex(3.0, 0.5, 0).x, 2);  // 2.5 -> 2 (even)
}

TEST(Coverage, SpanMethodsAgreeWithPerPixelTestAndOracle) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> small(-4.0, 40.0);
  std::uniform_real_distribution<double> huge(-3.0e5, 3.0e5);
  const PixelRect clip{0, 0, 37, 29};
  int covered_total = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    const int bits = iter % 13;
    Tri2 t;
    for (auto& v : t.v) {
      const bool big = iter % 7 == 0;
      v = big ? glm::dvec2(huge(rng) / (1 << bits), huge(rng) / (1 << bits))
              : glm::dvec2(small(rng), small(rng));
      // Half the time put vertices on the subpixel grid or on pixel centres (ties).
      if (iter % 3 == 1) v = glm::round(v * double(1 << bits)) / double(1 << bits);
      if (iter % 3 == 2) v = glm::floor(v) + 0.5;
    }
    bool ok = false;
    const TriangleCoverage c = setupCoverage(t, bits, clip, ok);
    // forEachSpan() (incremental for narrow triangles, by division for wide ones), per row.
    std::vector<std::pair<int, int>> spans(static_cast<std::size_t>(clip.y1), {0, 0});
    if (ok) {
      int last_row = -1;
      c.forEachSpan([&](int py, int x0, int x1) {
        ASSERT_GT(py, last_row);  // bottom to top, each row once
        last_row = py;
        spans[static_cast<std::size_t>(py)] = {x0, x1};
      });
    }
    for (int py = clip.y0; py < clip.y1; ++py) {
      int d0 = 0, d1 = 0, s0 = 0, s1 = 0;
      const bool by_div = ok && c.rowSpanByDivision(py, d0, d1);
      const bool by_scan = ok && c.rowSpanByScan(py, s0, s1);
      ASSERT_EQ(by_div, by_scan) << "iter " << iter << " row " << py;
      if (by_div) {
        ASSERT_EQ(d0, s0) << "iter " << iter;
        ASSERT_EQ(d1, s1) << "iter " << iter;
      }
      const auto [f0, f1] = spans[static_cast<std::size_t>(py)];
      ASSERT_EQ(by_div, f1 > f0) << "iter " << iter << " row " << py;
      if (by_div) {
        ASSERT_EQ(d0, f0) << "iter " << iter;
        ASSERT_EQ(d1, f1) << "iter " << iter;
      }
      for (int px = clip.x0; px < clip.x1; ++px) {
        const bool expected = oracleCovers(t, px, py, bits);
        const bool in_span = by_div && px >= d0 && px < d1;
        ASSERT_EQ(expected, in_span)
            << "iter " << iter << " pixel " << px << "," << py << " bits " << bits;
        ASSERT_EQ(expected, ok && c.covers(px, py));
        covered_total += expected;
      }
    }
  }
  EXPECT_GT(covered_total, 10000);  // the test exercised real coverage
}

TEST(Coverage, InjectedWrongTieRuleIsCaughtByTheOracle) {
  // The oracle must be able to fail: flipping the rule (right edges instead of left)
  // changes the coverage of a triangle with a vertical edge through centres.
  const Tri2 t{{{3.5, 0.0}, {8.0, 4.0}, {3.5, 8.0}}};
  EXPECT_TRUE(oracleCovers(t, 3, 4, 8));
  Tri2 mirrored{{{4.5, 0.0}, {0.0, 4.0}, {4.5, 8.0}}};  // vertical edge is its right edge
  EXPECT_FALSE(oracleCovers(mirrored, 4, 4, 8));
}

// ---- tie-break patterns measured on llvmpipe (through the whole renderer) ---------------

// Which triangle covers each pixel when each is rendered alone: rows top (y = H-1) first,
// a digit per covering triangle, '#' for several, '.' for none.
std::vector<std::string> coverageMap(int w, int h, const std::vector<Tri2>& tris,
                                     int subpixel_bits = 8) {
  std::vector<std::string> map(h, std::string(w, '.'));
  for (std::size_t k = 0; k < tris.size(); ++k) {
    Scene s = test::windowScene(w, h);
    const Tri2& t = tris[k];
    test::addTriangle(s, glm::vec3(glm::dvec2(t.v[0]), 0.5f), glm::vec3(glm::dvec2(t.v[1]), 0.5f),
                      glm::vec3(glm::dvec2(t.v[2]), 0.5f));
    ReferenceOptions opt;
    opt.subpixel_bits = subpixel_bits;
    const Frame f = renderReference(s, opt);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (f.id[f.index(x, y)] != 0) {
          char& c = map[y][x];
          c = c == '.' ? static_cast<char>('0' + k) : '#';
        }
  }
  return map;
}

TEST(TieBreak, VerticalSharedEdgeThroughCentresGoesToTheRightTriangle) {
  const auto map =
      coverageMap(8, 8, {{{{0, 0.5}, {3.5, 0}, {3.5, 8}}}, {{{3.5, 0}, {8, 4}, {3.5, 8}}}});
  const std::vector<std::string> llvmpipe = {"...1....", "...11...", "..0111..", "..01111.",
                                             ".001111.", ".00111..", "00011...", "0001...."};
  EXPECT_EQ(map, llvmpipe);
}

TEST(TieBreak, HorizontalSharedEdgeThroughCentresGoesToTheUpperTriangle) {
  const auto map =
      coverageMap(8, 8, {{{{0, 3.5}, {8, 3.5}, {4, 0}}}, {{{0, 3.5}, {4, 8}, {8, 3.5}}}});
  const std::vector<std::string> llvmpipe = {"........", "...11...", "..1111..", ".111111.",
                                             "11111111", ".000000.", "..0000..", "...00..."};
  EXPECT_EQ(map, llvmpipe);
}

TEST(TieBreak, DiagonalEdgesThroughCentres) {
  const auto diag = coverageMap(
      8, 8, {{{{0.5, 0.5}, {7.5, 7.5}, {0.5, 7.5}}}, {{{0.5, 0.5}, {7.5, 0.5}, {7.5, 7.5}}}});
  EXPECT_EQ(diag, (std::vector<std::string>{"........", "0000001.", "0000011.", "0000111.",
                                            "0001111.", "0011111.", "0111111.", "1111111."}));
  const auto anti = coverageMap(
      8, 8, {{{{0.5, 0.5}, {7.5, 0.5}, {0.5, 7.5}}}, {{{7.5, 0.5}, {7.5, 7.5}, {0.5, 7.5}}}});
  EXPECT_EQ(anti, (std::vector<std::string>{"........", "0111111.", "0011111.", "0001111.",
                                            "0000111.", "0000011.", "0000001.", "0000000."}));
}

TEST(TieBreak, SingleTrianglesWithVerticesOnCentresBothWindings) {
  const std::vector<std::string> lower_left = {"........", "........", ".0......", ".00.....",
                                               ".000....", ".0000...", ".00000..", "........"};
  EXPECT_EQ(coverageMap(8, 8, {{{{1.5, 1.5}, {1.5, 6.5}, {6.5, 1.5}}}}), lower_left);  // CW
  EXPECT_EQ(coverageMap(8, 8, {{{{1.5, 1.5}, {6.5, 1.5}, {1.5, 6.5}}}}), lower_left);  // CCW
  EXPECT_EQ(coverageMap(8, 8, {{{{6.5, 6.5}, {1.5, 6.5}, {6.5, 1.5}}}}),
            (std::vector<std::string>{"........", "........", "..0000..", "...000..", "....00..",
                                      ".....0..", "........", "........"}));
}

TEST(TieBreak, FourTrianglesMeetingAtAPixelCentre) {
  const auto map = coverageMap(8, 8,
                               {{{{3.5, 3.5}, {7, 0}, {7, 7}}},
                                {{{3.5, 3.5}, {7, 7}, {0, 7}}},
                                {{{3.5, 3.5}, {0, 7}, {0, 0}}},
                                {{{3.5, 3.5}, {0, 0}, {7, 0}}}});
  EXPECT_EQ(map, (std::vector<std::string>{"........", "1111110.", "2111100.", "2211000.",
                                           "2220000.", "2233000.", "2333300.", "3333330."}));
}

TEST(TieBreak, SnappingTiesMatchLlvmpipe) {
  const auto col = [](double x, bool right) {
    return right ? Tri2{{{x, 0}, {8, 4}, {x, 8}}} : Tri2{{{0, 4}, {x, 0}, {x, 8}}};
  };
  // Rows y = 7..0 of llvmpipe's output; only column 3 matters (centre x = 3.5).
  auto column3 = [&](double x, bool right) {
    std::string c;
    for (const auto& row : coverageMap(8, 8, {col(x, right)})) c += row[3];
    return c;
  };
  EXPECT_EQ(column3(3.5 + 1.0 / 512, true), "00000000");   // snaps to 3.5: left edge, covered
  EXPECT_EQ(column3(3.5 + 3.0 / 512, true), "........");   // snaps to 3.5 + 2/256
  EXPECT_EQ(column3(3.5 - 1.0 / 512, false), "........");  // snaps to 3.5: right edge, not covered
  EXPECT_EQ(column3(3.5 + 1.0 / 1024, false), "........");
  EXPECT_EQ(column3(3.5 + 1.0 / 256, false), "00000000");
}

TEST(TieBreak, SubpixelBitsOptionMovesTheSnapGrid) {
  // An edge at x = 3.7: with 8 bits the centre 3.5 is inside the left triangle; with 0
  // bits the vertex snaps to the centre 3.5 and the (right) edge excludes it.
  const Tri2 left{{{0, 4}, {3.7, 0}, {3.7, 8}}};
  EXPECT_EQ(coverageMap(8, 8, {left}, 8)[4][3], '0');
  EXPECT_EQ(coverageMap(8, 8, {left}, 0)[4][3], '.');
}

// ---- watertightness at the coverage level ------------------------------------------------

TEST(Coverage, JitteredGridCoversEveryPixelExactlyOnce) {
  std::mt19937 rng(3);
  const int n = 9;  // (n+1)^2 vertices spanning beyond a 48 x 40 viewport
  const PixelRect clip{0, 0, 48, 40};
  for (int variant = 0; variant < 3; ++variant) {
    std::vector<glm::dvec2> grid;
    std::uniform_real_distribution<double> jitter(-2.0, 2.0);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        glm::dvec2 p(-3.0 + i * 54.0 / n, -3.0 + j * 46.0 / n);
        if (i > 0 && i < n && j > 0 && j < n) p += glm::dvec2(jitter(rng), jitter(rng));
        if (variant == 1) p = glm::floor(p) + 0.5;            // on pixel centres
        if (variant == 2) p = glm::round(p * 256.0) / 256.0;  // on subpixel boundaries
        grid.push_back(p);
      }
    std::vector<int> hits(std::size_t{48} * 40, 0);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const glm::dvec2 a = grid[j * (n + 1) + i], b = grid[j * (n + 1) + i + 1];
        const glm::dvec2 c = grid[(j + 1) * (n + 1) + i], d = grid[(j + 1) * (n + 1) + i + 1];
        for (const Tri2& t : {Tri2{{a, b, d}}, Tri2{{a, d, c}}}) {
          bool ok = false;
          const TriangleCoverage cov = setupCoverage(t, 8, clip, ok);
          if (!ok) continue;
          cov.forEachSpan([&](int py, int x0, int x1) {
            for (int px = x0; px < x1; ++px) ++hits[py * 48 + px];
          });
        }
      }
    for (int i = 0; i < 48 * 40; ++i)
      ASSERT_EQ(hits[i], 1) << "variant " << variant << " pixel " << i % 48 << "," << i / 48;
  }
}

TEST(Coverage, FanAroundAPixelCentreCoversEveryPixelExactlyOnce) {
  const PixelRect clip{0, 0, 32, 32};
  const glm::dvec2 centre(15.5, 16.5);
  const int spokes = 37;
  const double pi = std::acos(-1.0);
  std::vector<int> hits(std::size_t{32} * 32, 0);
  for (int k = 0; k < spokes; ++k) {
    const double a0 = 2 * pi * k / spokes, a1 = 2 * pi * (k + 1) / spokes;
    const glm::dvec2 p0 = centre + 40.0 * glm::dvec2(std::cos(a0), std::sin(a0));
    const glm::dvec2 p1 = centre + 40.0 * glm::dvec2(std::cos(a1), std::sin(a1));
    bool ok = false;
    const TriangleCoverage cov = setupCoverage(Tri2{{centre, p0, p1}}, 8, clip, ok);
    if (!ok) continue;
    cov.forEachSpan([&](int py, int x0, int x1) {
      for (int px = x0; px < x1; ++px) ++hits[py * 32 + px];
    });
  }
  for (int i = 0; i < 32 * 32; ++i) ASSERT_EQ(hits[i], 1) << "pixel " << i % 32 << "," << i / 32;
}

TEST(Coverage, ZeroAreaAndSliverTriangles) {
  const PixelRect clip{0, 0, 16, 16};
  bool ok = true;
  setupCoverage(Tri2{{{1.5, 1.5}, {5.5, 5.5}, {9.5, 9.5}}}, 8, clip, ok);  // collinear
  EXPECT_FALSE(ok);
  setupCoverage(Tri2{{{2.0, 2.0}, {2.0, 2.0}, {9.0, 3.0}}}, 8, clip, ok);  // repeated vertex
  EXPECT_FALSE(ok);
  // Collinear after snapping only (offset 1/1024 px rounds away).
  setupCoverage(Tri2{{{1.5, 1.5}, {5.5 + 1.0 / 1024, 5.5}, {9.5, 9.5}}}, 8, clip, ok);
  EXPECT_FALSE(ok);
  // A sliver 1/64 px thick along the row of centres y = 4.5 covers exactly those centres
  // its (half-open) extent contains: the edge through them is the sliver's bottom edge.
  const Tri2 sliver{{{0.0, 4.5}, {16.0, 4.5}, {16.0, 4.5 + 1.0 / 64}}};
  const TriangleCoverage cov = setupCoverage(sliver, 8, clip, ok);
  ASSERT_TRUE(ok);
  for (int py = 0; py < 16; ++py)
    for (int px = 0; px < 16; ++px)
      EXPECT_EQ(cov.covers(px, py), oracleCovers(sliver, px, py, 8)) << px << "," << py;
  EXPECT_TRUE(cov.covers(8, 4));
  EXPECT_FALSE(cov.covers(8, 5));
}

}  // namespace
}  // namespace rc::ref

namespace rc::ref {
namespace {

// The prefetch box (prefetch.h) must hold every pixel the triangle covers, or the
// renderer asks for the wrong rows and pays the misses it was meant to hide; checked
// against the oracle on random small triangles at every subpixel precision, near and
// across the clip rectangle's sides.
TEST(PrefetchBox, HoldsEveryCoveredPixel) {
  std::mt19937 rng(20261203);
  std::uniform_real_distribution<double> corner(-3.0, 40.0);
  std::uniform_real_distribution<double> leg(-7.0, 7.0);
  const int x0 = 0;
  const int x1 = 37;
  const int y0 = 0;
  const int y1 = 29;
  int boxes = 0;
  for (const int bits : {0, 1, 4, 8}) {
    for (int n = 0; n < 3000; ++n) {
      Tri2 t;
      t.v[0] = {corner(rng), corner(rng)};
      t.v[1] = t.v[0] + glm::dvec2(leg(rng), leg(rng));
      t.v[2] = t.v[0] + glm::dvec2(leg(rng), leg(rng));
      const FixedVertex fixed[3] = {snapVertex(t.v[0].x, t.v[0].y, bits),
                                    snapVertex(t.v[1].x, t.v[1].y, bits),
                                    snapVertex(t.v[2].x, t.v[2].y, bits)};
      PixelBox box{};
      if (!PrefetchBox::worthPrefetching(fixed, bits, PixelRect{x0, y0, x1, y1}, box)) continue;
      ++boxes;
      for (int py = y0; py < y1; ++py) {
        for (int px = x0; px < x1; ++px) {
          if (!oracleCovers(t, px, py, bits)) continue;
          ASSERT_TRUE(px >= box.col_begin && px < box.col_end && py >= box.row_begin &&
                      py < box.row_end)
              << "pixel " << px << "," << py << " outside the box of triangle " << n << " at "
              << bits << " bits";
        }
      }
    }
  }
  EXPECT_GT(boxes, 3000);  // a third or more get a box: the test is not vacuous
}

TEST(PrefetchBox, IsTheSnappedBoxAndRefusesLargeOrOutsideTriangles) {
  PixelBox box{};
  const int bits = 4;
  const PixelRect clip{0, 0, 64, 64};
  const FixedVertex small[3] = {snapVertex(10.2, 20.4, bits), snapVertex(12.2, 20.4, bits),
                                snapVertex(10.2, 22.4, bits)};
  ASSERT_TRUE(PrefetchBox::worthPrefetching(small, bits, clip, box));
  EXPECT_EQ(box.col_begin, 10);  // centres 10.5 and 11.5
  EXPECT_EQ(box.col_end, 12);
  EXPECT_EQ(box.row_begin, 20);  // centres 20.5 and 21.5
  EXPECT_EQ(box.row_end, 22);
  const FixedVertex wide[3] = {snapVertex(0.0, 0.0, bits), snapVertex(40.0, 0.0, bits),
                               snapVertex(0.0, 2.0, bits)};
  EXPECT_FALSE(PrefetchBox::worthPrefetching(wide, bits, clip, box));
  const FixedVertex tall[3] = {snapVertex(0.0, 0.0, bits), snapVertex(2.0, 0.0, bits),
                               snapVertex(0.0, 30.0, bits)};
  EXPECT_FALSE(PrefetchBox::worthPrefetching(tall, bits, clip, box));
  // Outside the clip rectangle altogether: nothing to fetch.
  EXPECT_FALSE(PrefetchBox::worthPrefetching(small, bits, PixelRect{30, 0, 64, 64}, box));
}

}  // namespace
}  // namespace rc::ref
