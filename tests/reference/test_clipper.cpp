// Clipper: output inside the planes, barycentrics that reproduce the clipped positions,
// bit-identical cuts of shared edges, the guard band, trivial rejection.
#include <gtest/gtest.h>

#include <random>

#include "reference/clipper.h"
#include "reference/rasterizer.h"

namespace rc::ref {
namespace {

glm::dvec4 fromBary(const glm::dvec4 (&c)[3], const glm::dvec3& b) {
  return b.x * c[0] + b.y * c[1] + b.z * c[2];
}

TEST(Clipper, TriangleInsideIsUnchanged) {
  const ClipVolume vol = clipVolume(64, 64, guardLimitPx(8));
  ClipPolygon poly;
  const glm::dvec4 a(-0.5, -0.5, 0.1, 1.0), b(0.5, -0.5, 0.2, 1.0), c(0.0, 0.5, 0.3, 2.0);
  ASSERT_TRUE(clipTriangle(a, b, c, vol, poly));
  ASSERT_EQ(poly.count, 3);
  EXPECT_EQ(poly.v[0].clip, a);
  EXPECT_EQ(poly.v[2].clip, c);
  EXPECT_EQ(poly.v[1].bary, glm::dvec3(0.0, 1.0, 0.0));
}

TEST(Clipper, NearPlaneCutMatchesAnalyticIntersection) {
  const ClipVolume vol = clipVolume(64, 64, guardLimitPx(8));
  // Vertex 2 behind the near plane (z < -w): z + w goes 1 -> -1 along both edges to it.
  const glm::dvec4 a(0.0, 0.0, 0.0, 1.0), b(0.5, 0.0, 0.0, 1.0), c(0.0, 0.5, -2.0, 1.0);
  ClipPolygon poly;
  ASSERT_TRUE(clipTriangle(a, b, c, vol, poly));
  ASSERT_EQ(poly.count, 4);
  // b -> c crosses at t = 0.5, c -> a at t = 0.5 from a.
  EXPECT_EQ(poly.v[2].bary, glm::dvec3(0.0, 0.5, 0.5));
  EXPECT_EQ(poly.v[3].bary, glm::dvec3(0.5, 0.0, 0.5));
  for (int i = 0; i < poly.count; ++i) EXPECT_GE(poly.v[i].clip.z + poly.v[i].clip.w, 0.0);
}

TEST(Clipper, RandomTrianglesStayInsideAndBarycentricsReproducePositions) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> d(-3.0, 3.0);
  const ClipVolume vol = clipVolume(32, 16, guardLimitPx(12));  // a tight guard band
  int clipped = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    const double s = iter % 2 ? 1e5 : 1.0;  // some far beyond the guard band
    glm::dvec4 c[3];
    for (auto& v : c) v = glm::dvec4(d(rng) * s, d(rng) * s, d(rng), d(rng));
    ClipPolygon poly;
    if (!clipTriangle(c[0], c[1], c[2], vol, poly)) continue;
    ++clipped;
    ASSERT_GE(poly.count, 3);
    ASSERT_LE(poly.count, kMaxClipVertices);
    for (int i = 0; i < poly.count; ++i) {
      const glm::dvec4& p = poly.v[i].clip;
      const double tol = 1e-9 * (1.0 + glm::length(p));
      EXPECT_GE(p.z + p.w, -tol);
      EXPECT_GE(p.w - p.z, -tol);
      EXPECT_LE(std::abs(p.x), vol.guard_x * p.w + tol);
      EXPECT_LE(std::abs(p.y), vol.guard_y * p.w + tol);
      const glm::dvec4 q = fromBary(c, poly.v[i].bary);
      EXPECT_NEAR(q.x, p.x, tol * s);
      EXPECT_NEAR(q.w, p.w, tol * s);
      EXPECT_NEAR(poly.v[i].bary.x + poly.v[i].bary.y + poly.v[i].bary.z, 1.0, 1e-12);
    }
  }
  EXPECT_GT(clipped, 1000);
}

TEST(Clipper, SharedEdgeIsCutAtBitIdenticalPoints) {
  const ClipVolume vol = clipVolume(64, 64, guardLimitPx(8));
  // Edge a-b crosses the near plane; the triangles on both sides list it in opposite
  // directions.
  const glm::dvec4 a(0.1, 0.2, 0.3, 1.1), b(-0.3, 0.7, -3.7, 1.3);
  const glm::dvec4 c(0.9, 0.1, 0.2, 1.0), d(-0.8, -0.2, 0.1, 1.2);
  ClipPolygon p1, p2;
  ASSERT_TRUE(clipTriangle(a, b, c, vol, p1));
  ASSERT_TRUE(clipTriangle(b, a, d, vol, p2));
  int matches = 0;
  for (int i = 0; i < p1.count; ++i)
    for (int j = 0; j < p2.count; ++j)
      if (p1.v[i].clip == p2.v[j].clip && p1.v[i].clip != a) ++matches;
  EXPECT_EQ(matches, 1);  // the cut point on a-b, exactly equal
}

TEST(Clipper, GuardBandKeepsWindowCoordinatesWithinTheFixedPointBudget) {
  for (int bits : {0, 8, 12}) {
    const int w = 16384;
    const ClipVolume vol = clipVolume(w, 64, guardLimitPx(bits));
    EXPECT_GT(vol.guard_x, 1.0);
    // A huge triangle: every output vertex maps into [w - limit, limit].
    ClipPolygon poly;
    ASSERT_TRUE(clipTriangle({-1e12, -1e12, 0.0, 1.0}, {1e12, -1e12, 0.0, 1.0},
                             {0.0, 1e12, 0.0, 1.0}, vol, poly));
    for (int i = 0; i < poly.count; ++i) {
      const double xw = (poly.v[i].clip.x / poly.v[i].clip.w * 0.5 + 0.5) * w;
      EXPECT_LE(std::abs(xw), guardLimitPx(bits) * (1.0 + 1e-12)) << bits;
    }
  }
}

TEST(Clipper, TrivialRejectionOnlyBeyondTwoPixels) {
  const ClipVolume vol = clipVolume(64, 64, guardLimitPx(8));
  ClipPolygon poly;
  // Entirely right of the viewport by more than 2 px (x_ndc > 1 + 4/64).
  EXPECT_FALSE(clipTriangle({1.07, 0, 0, 1}, {1.5, 0, 0, 1}, {1.2, 0.5, 0, 1}, vol, poly));
  // Within the 2 px band: kept (its edges may lie within a pixel of the last column).
  EXPECT_TRUE(clipTriangle({1.01, 0, 0, 1}, {1.5, 0, 0, 1}, {1.2, 0.5, 0, 1}, vol, poly));
  // Entirely behind the near plane.
  EXPECT_FALSE(clipTriangle({0, 0, -2, 1}, {1, 0, -3, 1}, {0, 1, -2, 1}, vol, poly));
}

}  // namespace
}  // namespace rc::ref
