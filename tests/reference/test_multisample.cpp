// Multisampling in the reference against answers computed without it: per-sample coverage
// of a half-plane at the standard positions (2, 4, 8 samples) and the resolved colour
// from those counts; the catalog's shared fan, where every sample inside the fan's
// outline must be covered exactly once; determinism; positions taken as input.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/multisample.h"
#include "reference/reference_renderer.h"

namespace rc {
namespace {

constexpr int kSize = 32;

// Orthographic camera with window coordinates equal to world x, y (bounds [0, size]).
Scene windowScene(int samples) {
  Scene s;
  s.name = "test/msaa";
  s.width = kSize;
  s.height = kSize;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 1.0};
  s.camera.bounds = {0.0, kSize, 0.0, kSize};
  s.camera.near = 0.5;
  s.camera.far = 2.0;
  s.ambient_light = glm::dvec3(1.0);
  Material m;
  m.ambient = {0.25, 0.5, 0.75};
  m.diffuse = glm::dvec3(0.0);
  s.materials.push_back(m);
  s.state.shading = Shading::Flat;
  s.state.samples = samples;
  return s;
}

Object triangle(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  Object o;
  o.name = "t";
  o.mesh.positions = {{a.x, a.y, 0.0}, {b.x, b.y, 0.0}, {c.x, c.y, 0.0}};
  o.mesh.normals.assign(3, glm::vec3(0, 0, 1));
  o.mesh.triangles = {{0, 1, 2}};
  return o;
}

double cross(glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; }

// One triangle whose edge a -> b crosses the image and whose other edges lie outside it:
// a sample is covered iff it is on c's side of the line ab (vertices on the 1/256 grid,
// so snapping at 8 bits moves nothing; samples exactly on the line are not checked).
TEST(ReferenceMultisample, HalfPlaneCoverageAtTheStandardPositions) {
  const glm::dvec2 a(-20.5, 3.25), b(90.75, 50.5), c(-20.5, 200.0);
  for (int samples : {2, 4, 8}) {
    Scene s = windowScene(samples);
    s.objects.push_back(triangle(a, b, c));
    const Frame f = renderReference(s);
    ASSERT_EQ(f.samples, samples);
    const std::vector<glm::dvec2> pos = standardSamplePositions(samples);
    const double side = cross(b - a, c - a);
    int partial = 0;
    for (int y = 0; y < kSize; ++y) {  // GL window row
      for (int x = 0; x < kSize; ++x) {
        const std::size_t i = f.index(x, kSize - 1 - y);
        int covered = 0;
        bool on_line = false;
        for (int k = 0; k < samples; ++k) {
          const double e = cross(b - a, glm::dvec2(x, y) + pos[k] - a);
          if (e == 0.0) {
            on_line = true;
            continue;
          }
          const bool inside = (e > 0.0) == (side > 0.0);
          EXPECT_EQ(f.sample_id[f.sampleIndex(k, i)], inside ? 1u : 0u)
              << samples << " samples, pixel " << x << "," << y << " sample " << k;
          covered += inside ? 1 : 0;
        }
        if (on_line) continue;
        partial += covered > 0 && covered < samples ? 1 : 0;
        // Resolve: the mean of the samples (background 0), and the owner rule.
        const double frac = static_cast<double>(covered) / samples;
        EXPECT_NEAR(f.color[i * 4 + 0], 0.25 * frac, 1e-6);
        EXPECT_NEAR(f.color[i * 4 + 2], 0.75 * frac, 1e-6);
        EXPECT_NEAR(f.color[i * 4 + 3], frac, 1e-6);
        const bool owner_is_prim =
            2 * covered > samples ||
            (2 * covered == samples && f.sample_id[f.sampleIndex(0, i)] == 1u);
        EXPECT_EQ(f.id[i], owner_is_prim ? 1u : 0u) << x << "," << y;
        EXPECT_EQ(f.coverage[i], owner_is_prim ? covered : samples - covered) << x << "," << y;
      }
    }
    EXPECT_GT(partial, kSize / 4) << samples << " samples: the edge crosses the image";
  }
}

// A wrong sample position is a different image: the fault a driver comparison must see.
TEST(ReferenceMultisample, GivenPositionsAreUsed) {
  Scene s = windowScene(4);
  s.objects.push_back(triangle({-20.5, 3.25}, {90.75, 50.5}, {-20.5, 200.0}));
  const Frame standard = renderReference(s);
  ReferenceOptions mirrored;
  for (const glm::dvec2& p : standardSamplePositions(4))
    mirrored.sample_positions.emplace_back(p.x, 1.0 - p.y);
  const Frame other = renderReference(s, mirrored);
  EXPECT_NE(standard.sample_id, other.sample_id);
  EXPECT_EQ(other.meta["multisample"]["positions_source"], "given");
  EXPECT_EQ(standard.meta["multisample"]["positions_source"], "standard");
  ReferenceOptions wrong_count;
  wrong_count.sample_positions = {{0.5, 0.5}};
  EXPECT_THROW(renderReference(s, wrong_count), InputError);
}

TEST(ReferenceMultisample, StandardFourSamplePatternIsWhatLlvmpipeReports) {
  const std::vector<glm::dvec2> want = {
      {0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
  EXPECT_EQ(standardSamplePositions(4), want);
  EXPECT_TRUE(standardSamplePositions(3).empty());
}

bool insideConvex(const std::vector<glm::dvec2>& poly, glm::dvec2 p, double margin, bool& near) {
  bool inside = true;
  near = false;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const glm::dvec2 a = poly[k], b = poly[(k + 1) % poly.size()];
    const double d = cross(b - a, p - a) / glm::length(b - a);  // > 0 inside (ccw)
    if (std::fabs(d) <= margin) near = true;
    if (d < 0.0) inside = false;
  }
  return inside;
}

// The catalog's fan: twelve triangles around one centre. Inside its outline every sample is
// covered by exactly one triangle: the fragments (covered samples, whether they passed the
// depth test or not) equal the samples showing a triangle, and those are the samples inside
// the outline (analytic, except within 0.01 px of it, where snapping may decide).
TEST(ReferenceMultisample, SharedFanCoversEverySampleExactlyOnce) {
  const Scene s =
      loadScene(std::filesystem::path(RC_SOURCE_DIR) / "fixtures/scenes/msaa/shared_fan.json");
  const Frame f = renderReference(s);
  ASSERT_EQ(f.samples, 4);
  std::vector<glm::dvec2> outline;  // window coordinates: bounds [-1, 1] over the image
  for (const Object& o : s.objects) {
    const glm::vec3 p = o.mesh.positions[1];
    outline.emplace_back((p.x + 1.0) * 0.5 * s.width, (p.y + 1.0) * 0.5 * s.height);
  }
  const std::vector<glm::dvec2> pos = standardSamplePositions(4);
  std::uint64_t shown = 0;
  int checked = 0;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const std::size_t i = f.index(x, s.height - 1 - y);
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t id = f.sample_id[f.sampleIndex(k, i)];
        shown += id != 0 ? 1 : 0;
        bool near = false;
        const bool inside = insideConvex(outline, glm::dvec2(x, y) + pos[k], 0.01, near);
        if (near) continue;
        ++checked;
        EXPECT_EQ(id != 0, inside) << "pixel " << x << "," << y << " sample " << k;
      }
    }
  }
  EXPECT_GT(checked, 4 * s.width * s.height * 9 / 10);
  EXPECT_EQ(f.meta["fragments"].get<std::uint64_t>(), shown) << "a sample covered twice";
}

TEST(ReferenceMultisample, Deterministic) {
  const Scene s = loadScene(std::filesystem::path(RC_SOURCE_DIR) /
                            "fixtures/scenes/msaa/interpenetrating.json");
  const Frame a = renderReference(s);
  const Frame b = renderReference(s);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.sample_id, b.sample_id);
  EXPECT_EQ(a.sample_depth, b.sample_depth);
  EXPECT_EQ(a.sample_edge_dist, b.sample_edge_dist);
  EXPECT_EQ(a.sample_alt, b.sample_alt);
  EXPECT_EQ(a.depth_gap, b.depth_gap);
}

}  // namespace
}  // namespace rc
