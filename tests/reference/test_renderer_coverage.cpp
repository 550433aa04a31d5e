// Coverage through the whole renderer: watertight meshes (also after near clipping),
// the analytic horizon of a ground plane that crosses the camera plane, triangles far
// larger than the view, culling, degenerate input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fixtures/scene_logic.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

// A (n+1) x (n+1) vertex grid over [a0, a1] x [b0, b1] at `level`, in the xz-plane
// (perspective scenes) or the xy-plane (window scenes), interior vertices jittered (keep
// jitter below a quarter of the spacing, or quads fold and triangles overlap).
Mesh gridMesh(int n, double a0, double a1, double b0, double b1, bool xz_plane, double level,
              double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> j(-jitter, jitter);
  Mesh m;
  for (int r = 0; r <= n; ++r)
    for (int c = 0; c <= n; ++c) {
      double a = a0 + (a1 - a0) * c / n;
      double b = b0 + (b1 - b0) * r / n;
      if (r > 0 && r < n && c > 0 && c < n) {
        a += j(rng);
        b += j(rng);
      }
      m.positions.push_back(xz_plane ? glm::vec3(a, level, b) : glm::vec3(a, b, level));
      m.normals.emplace_back(0.0f, xz_plane ? 1.0f : 0.0f, xz_plane ? 0.0f : 1.0f);
    }
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const std::uint32_t i = r * (n + 1) + c;
      m.triangles.push_back({i, i + 1, i + n + 2});
      m.triangles.push_back({i, i + n + 2, i + n + 1});
    }
  return m;
}

// Hits per pixel when every triangle of object 0 is rendered on its own.
std::vector<int> hitsPerPixel(const Scene& scene) {
  std::vector<int> hits(static_cast<std::size_t>(scene.width) * scene.height, 0);
  const Mesh& mesh = scene.objects[0].mesh;
  for (const auto& tri : mesh.triangles) {
    Scene one = scene;
    one.objects[0].mesh.triangles = {tri};
    const Frame f = renderReference(one);
    for (std::size_t i = 0; i < hits.size(); ++i) hits[i] += f.id[i] != 0;
  }
  return hits;
}

TEST(RendererCoverage, JitteredWindowGridIsWatertight) {
  for (unsigned seed : {1u, 2u}) {
    Scene s = test::windowScene(64, 48);
    Object o;
    o.mesh = gridMesh(10, -5.0, 70.0, -4.0, 53.0, false, 0.5, 1.4, seed);  // no folds
    s.objects.push_back(o);
    const std::vector<int> hits = hitsPerPixel(s);
    for (std::size_t i = 0; i < hits.size(); ++i)
      ASSERT_EQ(hits[i], 1) << "seed " << seed << " pixel " << i % 64 << "," << i / 64;
    // The whole mesh at once: every pixel shows some primitive.
    const Frame f = renderReference(s);
    for (std::uint32_t id : f.id) ASSERT_NE(id, 0u);
  }
}

// A ground plane y = 0 under a perspective camera at height 1 looking horizontally: its
// two triangles run from 1000 units behind the camera to 1000 in front, so both cross
// the camera plane and are clipped at the near plane. A pixel row is covered iff the ray
// through its centre descends steeply enough to meet the plane within 1000 units.
TEST(RendererCoverage, GroundPlaneCrossingTheCameraPlaneFollowsTheHorizon) {
  Scene s;
  s.width = 64;
  s.height = 64;
  s.camera.eye = {0.0, 1.0, 0.0};
  s.camera.target = {0.0, 1.0, -1.0};
  s.camera.fovy_deg = 90.0;
  s.camera.near = 0.1;
  s.camera.far = 1.0e5;
  s.ambient_light = glm::dvec3(1.0);
  Material m;
  m.ambient = glm::dvec3(1.0);
  s.materials.push_back(m);
  test::addMesh(s, {{-1000, 0, 1000}, {1000, 0, 1000}, {1000, 0, -1000}, {-1000, 0, -1000}},
                {{0, 1, 2}, {0, 2, 3}}, 0, {0, 1, 0});
  const Frame f = renderReference(s);
  const double n = s.camera.near, far = s.camera.far;
  for (int y = 0; y < 64; ++y) {
    const int gl_row = 63 - y;
    // Ray slope below the horizon: tan(45 deg) * (32 - (row + 0.5)) / 32.
    const double slope = (32.0 - (gl_row + 0.5)) / 32.0;
    const bool covered = slope > 0.0 && 1.0 / slope <= 1000.0;
    for (int x = 0; x < 64; ++x) {
      ASSERT_EQ(f.id[f.index(x, y)] != 0, covered) << "pixel " << x << "," << y;
      if (!covered) continue;
      // View depth 1/slope; window z of the perspective projection (GL, [0, 1]).
      const double d = 1.0 / slope;
      const double z_ndc = (far + n) / (far - n) - 2.0 * far * n / ((far - n) * d);
      const double expected = z_ndc * 0.5 + 0.5;
      EXPECT_NEAR(f.depth[f.index(x, y)], expected, 2.0 / 16777215.0) << x << "," << y;
    }
  }
}

// A tessellated ground plane seen in perspective, crossing the near plane: clipped
// shared edges stay watertight (each pixel at most once, and exactly once well inside).
TEST(RendererCoverage, ClippedTessellatedPlaneIsWatertight) {
  Scene s;
  s.width = 48;
  s.height = 32;
  s.camera.eye = {0.0, 0.0, 0.0};
  s.camera.target = {0.0, -0.4, -1.0};
  s.camera.fovy_deg = 70.0;
  s.camera.near = 0.5;
  s.camera.far = 100.0;
  Material m;
  m.ambient = glm::dvec3(1.0);
  s.materials.push_back(m);
  Object o;
  o.mesh = gridMesh(12, -20.0, 20.0, -20.0, 20.0, true, -1.0, 0.9, 5);
  s.objects.push_back(o);
  const std::vector<int> hits = hitsPerPixel(s);
  const glm::dmat4 inv = glm::inverse(projectionMatrix(s.camera, 1.5) * viewMatrix(s.camera));
  int inside = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 48; ++x) {
      const int h = hits[static_cast<std::size_t>(y) * 48 + x];
      ASSERT_LE(h, 1) << x << "," << y;
      // Ray through the pixel centre hits y = -1 at a point well inside the plane's extent
      // and beyond the near plane: must be covered exactly once.
      const double nx = 2.0 * (x + 0.5) / 48 - 1.0, ny = 2.0 * ((31 - y) + 0.5) / 32 - 1.0;
      glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
      const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
      if (!(p1.y < p0.y)) continue;
      const double t = (-1.0 - p0.y) / (p1.y - p0.y);
      const glm::dvec3 hit = p0 + t * (p1 - p0);
      if (t > 0.0 && t < 1.0 && std::abs(hit.x) < 18.0 && std::abs(hit.z) < 18.0) {
        ASSERT_EQ(h, 1) << x << "," << y;
        ++inside;
      }
    }
  EXPECT_GT(inside, 300);
}

TEST(RendererCoverage, TrianglesFarLargerThanTheView) {
  // Orthographic: vertices at +/- 1e7 px, a tilted plane: every pixel, depth on the plane.
  Scene s = test::windowScene(64, 64);
  test::addTriangle(s, {-1e7f, -1e7f, 0.25f}, {1e7f, -1e7f, 0.25f}, {0.0f, 1e7f, 0.75f});
  Frame f = renderReference(s);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      ASSERT_EQ(f.id[f.index(x, y)], 1u);
      // z = 0.25 + 0.5 * (Y + 1e7) / 2e7 along y (window y = 63 - y + 0.5), depth 1 - z.
      const double yw = 63 - y + 0.5;
      const double expected = 1.0 - (0.25 + 0.5 * (yw + 1e7) / 2e7);
      EXPECT_NEAR(f.depth[f.index(x, y)], expected, 1.5 / 16777215.0);
    }
  // Perspective: a 2e6-unit triangle 5 units in front of the camera.
  Scene p;
  p.width = 32;
  p.height = 32;
  p.materials.push_back(Material{});
  test::addTriangle(p, {-1e6f, -1e6f, 0.0f}, {1e6f, -1e6f, 0.0f}, {0.0f, 1e6f, 0.0f});
  f = renderReference(p);
  for (std::uint32_t id : f.id) ASSERT_EQ(id, 1u);
}

struct CullCase {
  bool ccw_vertices;
  FrontFace front;
  Cull cull;
  bool drawn;
};

TEST(RendererCoverage, CullingByWindowSpaceWindingAndFrontFace) {
  const CullCase cases[] = {
      {true, FrontFace::CCW, Cull::None, true},   {false, FrontFace::CCW, Cull::None, true},
      {true, FrontFace::CCW, Cull::Back, true},   {false, FrontFace::CCW, Cull::Back, false},
      {true, FrontFace::CCW, Cull::Front, false}, {false, FrontFace::CCW, Cull::Front, true},
      {true, FrontFace::CW, Cull::Back, false},   {false, FrontFace::CW, Cull::Back, true},
      {true, FrontFace::CW, Cull::Front, true},   {false, FrontFace::CW, Cull::Front, false},
  };
  for (const CullCase& c : cases) {
    Scene s = test::windowScene(16, 16);
    s.state.front_face = c.front;
    s.state.cull = c.cull;
    const glm::vec3 a(1, 1, 0.5f), b(15, 1, 0.5f), d(1, 15, 0.5f);  // a, b, d is CCW
    if (c.ccw_vertices)
      test::addTriangle(s, a, b, d);
    else
      test::addTriangle(s, a, d, b);
    const Frame f = renderReference(s);
    EXPECT_EQ(f.id[f.index(4, 11)] != 0, c.drawn)
        << "ccw " << c.ccw_vertices << " front " << toString(c.front) << " cull "
        << toString(c.cull);
  }
}

TEST(RendererCoverage, ZeroAreaAndDegenerateTrianglesProduceNoFragments) {
  Scene s = test::windowScene(16, 16);
  test::addTriangle(s, {1.5f, 1.5f, 0.5f}, {5.5f, 5.5f, 0.5f}, {9.5f, 9.5f, 0.5f});
  test::addTriangle(s, {3.0f, 3.0f, 0.5f}, {3.0f, 3.0f, 0.5f}, {3.0f, 3.0f, 0.5f});
  test::addTriangle(s, {0.0f, 7.5f, 0.5f}, {16.0f, 7.5f, 0.5f}, {8.0f, 7.5f, 0.5f});
  const Frame f = renderReference(s);
  for (std::uint32_t id : f.id) EXPECT_EQ(id, 0u);
}

TEST(RendererCoverage, SliverCoversOnlyTheCentresItContains) {
  Scene s = test::windowScene(16, 16);
  // 1/16 px thick, along y = 4.5 .. 4.5625: its bottom edge runs through the centres of
  // row 4, which the bottom-edge rule includes; nothing else.
  test::addTriangle(s, {0.25f, 4.5f, 0.5f}, {15.75f, 4.5f, 0.5f}, {15.75f, 4.5625f, 0.5f});
  const Frame f = renderReference(s);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) EXPECT_EQ(f.id[f.index(x, y)] != 0, y == 11 && x <= 15) << x;
}

TEST(RendererCoverage, TraceCountsOneFragmentPerPixelOnAWatertightMesh) {
  Scene s = test::windowScene(24, 16);
  Object o;
  o.mesh = gridMesh(5, -2.0, 26.0, -2.0, 18.0, false, 0.5, 1.5, 9);
  s.objects.push_back(o);
  const Frame f = renderReference(s);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 24; ++x) {
      const auto trace = tracePixel(s, {}, x, y);
      ASSERT_EQ(trace.size(), 1u) << x << "," << y;
      EXPECT_EQ(trace[0].primitive, f.id[f.index(x, y)]);
    }
}

}  // namespace
}  // namespace rc
