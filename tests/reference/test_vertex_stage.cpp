// The vertex stage's and the per-vertex window set-up's vector code (reference/vertex_stage.cpp,
// reference/vertex_windows.cpp) against the scalar functions they stand for, bit for bit,
// in both builds (x86-64's baseline and AVX2): GLM's mat4 * vec4 for world and clip,
// the clip error bound's formula, toWindow(), snapVertexScaled() and the per-vertex tests of
// classifyTriangle(), on random vertices and on every edge the code branches on (NaN and
// infinite coordinates, w <= 0, -0, points exactly on the clip, guard and reject planes,
// snapping ties, magnitudes past 2^52 units) and on counts that leave partial vectors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "fixtures/scene_geometry.h"
#include "reference/clipper.h"
#include "reference/rasterizer.h"
#include "reference/reference_renderer.h"
#include "reference/vertex_stage.h"
#include "reference/vertex_windows.h"
#include "reference/viewport.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

using namespace rc::ref;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool sameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

::testing::AssertionResult sameVec(const double* a, const double* b, int n) {
  for (int k = 0; k < n; ++k)
    if (!sameBits(a[k], b[k]))
      return ::testing::AssertionFailure()
             << "component " << k << ": " << a[k] << " vs " << b[k] << " (bits differ)";
  return ::testing::AssertionSuccess();
}

using TransformFn = void (*)(const glm::dmat4&, const glm::dmat4&, const glm::dmat4&,
                             const glm::vec3*, std::size_t, TransformedVertex*, bool);
using WindowFn = void (*)(const TransformedVertex*, std::size_t, const WindowSetup&, VertexWindow*);

// The builds this CPU can run.
std::vector<TransformFn> transformBuilds() {
  std::vector<TransformFn> fns = {detail::transformPositionsBaseline};
  if (__builtin_cpu_supports("avx2")) fns.push_back(detail::transformPositionsAvx2);
  return fns;
}
std::vector<WindowFn> windowBuilds() {
  std::vector<WindowFn> fns = {detail::setUpVertexWindowsBaseline};
  if (__builtin_cpu_supports("avx2")) fns.push_back(detail::setUpVertexWindowsAvx2);
  return fns;
}

glm::dmat4 randomMatrix(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> d(-3.0, 3.0);
  glm::dmat4 m;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = d(rng);
  return m;
}

TEST(VertexStage, PositionsMatchGlmBitForBit) {
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<float> pos(-100.0f, 100.0f);
  for (int round = 0; round < 20; ++round) {
    const glm::dmat4 model = randomMatrix(rng);
    const glm::dmat4 vp = randomMatrix(rng);
    glm::dmat4 abs_vp(0.0);
    for (int c = 0; c < 4; ++c) abs_vp[c] = glm::abs(vp[c]);
    std::vector<glm::vec3> positions = {{std::numeric_limits<float>::quiet_NaN(), 1.0f, 2.0f},
                                        {std::numeric_limits<float>::infinity(), -0.0f, 0.0f},
                                        {-0.0f, -0.0f, -0.0f},
                                        {3.0e38f, -3.0e38f, 1.0e-45f}};
    positions.reserve(positions.size() + 37);
    for (int i = 0; i < 37; ++i) {
      const float x = pos(rng);
      const float y = pos(rng);
      const float z = pos(rng);
      positions.emplace_back(x, y, z);
    }
    for (const TransformFn fn : transformBuilds()) {
      for (const bool errors : {false, true}) {
        std::vector<TransformedVertex> out(positions.size());
        fn(model, vp, abs_vp, positions.data(), positions.size(), out.data(), errors);
        for (std::size_t i = 0; i < positions.size(); ++i) {
          const TransformedVertex d =
              transformPositionDefinition(model, vp, abs_vp, positions[i], errors);
          EXPECT_TRUE(sameVec(&out[i].world.x, &d.world.x, 3)) << "vertex " << i;
          EXPECT_TRUE(sameVec(&out[i].clip.x, &d.clip.x, 4)) << "vertex " << i;
          EXPECT_TRUE(sameVec(&out[i].clip_err.x, &d.clip_err.x, 4)) << "vertex " << i;
          // The definition is GLM's mat4 * vec4 of the world position.
          const glm::dvec3 world = worldPosition(model, positions[i]);
          EXPECT_TRUE(sameVec(&d.world.x, &world.x, 3)) << "vertex " << i;
        }
      }
    }
  }
}

// The renderer transforms an object in pieces (ObjectTransform::apply on ranges): every
// field of every vertex must come out as one whole transformObject() gives it, normals,
// uvs (some vertices without: the mesh's arrays shorter) and error bounds included.
TEST(VertexStage, RangesMatchTheWholeObjectBitForBit) {
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<float> d(-50.0f, 50.0f);
  Object object;
  object.model = randomMatrix(rng);
  for (int i = 0; i < 1000; ++i) object.mesh.positions.emplace_back(d(rng), d(rng), d(rng));
  for (int i = 0; i < 990; ++i) object.mesh.normals.emplace_back(d(rng), d(rng), d(rng));
  for (int i = 0; i < 700; ++i) object.mesh.uvs.emplace_back(d(rng), d(rng));
  CameraTransform camera;
  camera.view_projection = randomMatrix(rng);
  for (const bool normals : {false, true}) {
    for (const bool errors : {false, true}) {
      std::vector<TransformedVertex> whole;
      transformObject(object, camera, whole, normals, errors);
      std::vector<TransformedVertex> pieces(whole.size());
      const ObjectTransform transform(object, camera, normals, errors);
      std::size_t begin = 0;
      for (const std::size_t size : {1, 7, 512, 480}) {
        transform.apply(begin, begin + size, pieces.data());
        begin += size;
      }
      ASSERT_EQ(begin, whole.size());
      for (std::size_t i = 0; i < whole.size(); ++i) {
        const TransformedVertex& a = pieces[i];
        const TransformedVertex& b = whole[i];
        EXPECT_TRUE(sameVec(&a.world.x, &b.world.x, 3)) << "vertex " << i;
        EXPECT_TRUE(sameVec(&a.normal.x, &b.normal.x, 3)) << "vertex " << i;
        EXPECT_TRUE(sameVec(&a.clip.x, &b.clip.x, 4)) << "vertex " << i;
        EXPECT_TRUE(sameVec(&a.uv.x, &b.uv.x, 2)) << "vertex " << i;
        EXPECT_TRUE(sameVec(&a.clip_err.x, &b.clip_err.x, 4)) << "vertex " << i;
      }
    }
  }
}

// A flat, unlit, untextured object's vertex records are written only once a vertex lies
// outside the clip volume (Renderer::transformVertices()): before that each piece of 512
// goes to one reused buffer, and at the first vertex outside the pieces so far are
// transformed again into the object's array. Here a clipped triangle (one vertex beyond the
// far plane, at index 1500, in the third piece) also uses vertices 3 and 4 of the first
// piece, and the same scene with one unused vertex outside put first (so that every record
// is written from the start) must give the same frame bit for bit. (Tried: without the
// second transform of the earlier pieces this fails.)
TEST(VertexStage, RecordsSkippedWhileInsideGiveTheSameFrame) {
  std::mt19937 rng(20261203);
  std::uniform_real_distribution<float> x(1.0f, 63.0f);
  std::uniform_real_distribution<float> y(1.0f, 47.0f);
  std::uniform_real_distribution<float> z(0.1f, 0.9f);
  std::vector<glm::vec3> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (std::uint32_t i = 0; i < 1500; i += 3) {
    const glm::vec3 p(x(rng), y(rng), z(rng));
    positions.push_back(p);
    positions.push_back(p + glm::vec3(3.0f, 0.5f, 0.0f));
    positions.push_back(p + glm::vec3(0.5f, 3.0f, 0.01f));
    triangles.push_back({i, i + 1, i + 2});
  }
  // Vertices 3 and 4 with one beyond the far plane (window scenes look down -z from z = 1,
  // far at 1): drawn clipped, late in the draw order.
  positions.emplace_back(40.0f, 30.0f, -3.0f);
  triangles.push_back({3, 4, 1500});
  for (int i = 0; i < 100; ++i) positions.emplace_back(x(rng), y(rng), 0.5f);  // unused
  ASSERT_GT(positions.size(), 3u * 512u);

  Scene late = test::windowScene(64, 48);
  late.state.shading = Shading::Flat;
  test::addMesh(late, positions, triangles, 0, glm::vec3(0.0f, 0.0f, 1.0f), {});
  Scene first = late;
  Mesh& mesh = first.objects[0].mesh;
  mesh.positions.insert(mesh.positions.begin(), glm::vec3(10.0f, 10.0f, 5.0f));
  mesh.normals.insert(mesh.normals.begin(), glm::vec3(0.0f, 0.0f, 1.0f));
  for (auto& t : mesh.triangles)
    for (auto& v : t) ++v;

  for (const bool uncertainty : {false, true}) {
    ReferenceOptions o;
    o.uncertainty = uncertainty;
    const Frame a = renderReference(late, o);
    const Frame b = renderReference(first, o);
    EXPECT_TRUE(test::frameBytes(a) == test::frameBytes(b)) << "uncertainty " << uncertainty;
    // The clipped triangle is drawn (its id is seen), so the test reads those records.
    EXPECT_NE(std::count(a.id.begin(), a.id.end(), 501u), 0) << "uncertainty " << uncertainty;
  }
}

// vertexWindowDefinition() of a vertex, checked against the stage it restates: its band
// flags must be what classifyTriangle() of three copies of the vertex says.
VertexWindow expected(const glm::dvec4& c, const WindowSetup& s) {
  const VertexWindow e = vertexWindowDefinition(c, s);
  if ((e.flags & VertexWindow::kInside) != 0) {
    const ClipClass whole = classifyTriangle(c, c, c, s.volume);
    EXPECT_EQ(whole == ClipClass::Rejected, (e.flags >> VertexWindow::kRejectShift) != 0)
        << "the band test disagrees";
  }
  return e;
}

void expectWindowsMatch(const std::vector<glm::dvec4>& clips, const WindowSetup& setup) {
  std::vector<TransformedVertex> verts(clips.size());
  for (std::size_t i = 0; i < clips.size(); ++i) verts[i].clip = clips[i];
  for (const WindowFn fn : windowBuilds()) {
    // Every count from 0 to 5 past a multiple of four: partial vectors at the end.
    for (std::size_t count = clips.size() >= 5 ? clips.size() - 5 : 0; count <= clips.size();
         ++count) {
      std::vector<VertexWindow> out(clips.size() + 1);
      out.back().flags = 0xee;  // past the end: must stay as it is
      fn(verts.data(), count, setup, out.data());
      EXPECT_EQ(out.back().flags, 0xee);
      for (std::size_t i = 0; i < count; ++i) {
        const VertexWindow e = expected(clips[i], setup);
        const VertexWindow& w = out[i];
        ASSERT_EQ(w.flags, e.flags)
            << "vertex " << i << " clip (" << clips[i].x << ", " << clips[i].y << ", " << clips[i].z
            << ", " << clips[i].w << ")";
        if ((e.flags & VertexWindow::kDrawable) == 0) continue;
        EXPECT_TRUE(sameBits(w.x, e.x) && sameBits(w.y, e.y) && sameBits(w.z, e.z) &&
                    sameBits(w.inv_w, e.inv_w))
            << "vertex " << i;
        EXPECT_EQ(w.fixed.x, e.fixed.x) << "vertex " << i;
        EXPECT_EQ(w.fixed.y, e.fixed.y) << "vertex " << i;
      }
    }
  }
}

WindowSetup setupFor(int width, int height, int bits) {
  WindowSetup s;
  s.width = width;
  s.height = height;
  s.snap_scale = std::ldexp(1.0, bits);
  s.volume = clipVolume(width, height, guardLimitPx(bits));
  return s;
}

TEST(VertexWindows, RandomVerticesMatchTheScalarStagesBitForBit) {
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<double> near(-1.5, 1.5);
  std::uniform_real_distribution<double> far(-3000.0, 3000.0);
  std::uniform_real_distribution<double> w(-0.5, 4.0);
  for (const int bits : {0, 4, 8, 12}) {
    for (const auto& [width, height] : {std::pair{640, 480}, std::pair{1, 1}, {16384, 3}}) {
      WindowSetup setup = setupFor(width, height, bits);
      std::vector<glm::dvec4> clips;
      for (int i = 0; i < 403; ++i) {
        const double ww = w(rng);
        auto coord = [&] { return (i % 3 == 0 ? far(rng) : near(rng)) * std::fabs(ww); };
        const double x = coord();
        const double y = coord();
        const double z = near(rng) * ww;
        clips.emplace_back(x, y, z, ww);
      }
      expectWindowsMatch(clips, setup);
      setup.shift_x = 3;  // a sample shift (multisampling)
      setup.shift_y = -5;
      expectWindowsMatch(clips, setup);
    }
  }
}

TEST(VertexWindows, EdgeCasesMatchTheScalarStages) {
  for (const int bits : {0, 8}) {
    const WindowSetup setup = setupFor(200, 100, bits);
    const double gx = setup.volume.guard_x;
    const double rx = setup.volume.reject_x;
    const double ry = setup.volume.reject_y;
    std::vector<glm::dvec4> clips = {
        {kNaN, 0.0, 0.0, 1.0},
        {0.0, 0.0, 0.0, kNaN},
        {kInf, 0.0, 0.0, 1.0},
        {0.0, -kInf, 0.0, 1.0},
        {0.0, 0.0, 0.0, 0.0},  // inside every plane at w = 0: not drawable
        {-0.0, -0.0, -0.0, 0.0},
        {0.0, 0.0, 0.0, -1.0},  // w < 0
        {0.0, 0.0, 0.0, 1e-300},
        {0.0, 0.0, 1.0, 1.0},   // on the far plane
        {0.0, 0.0, -1.0, 1.0},  // on the near plane
        {0.0, 0.0, 1.0000001, 1.0},
        {gx * 2.0, 0.0, 0.0, 2.0},  // on the guard plane
        {-gx * 2.0, 0.0, 0.0, 2.0},
        {std::nextafter(gx * 2.0, kInf), 0.0, 0.0, 2.0},
        {rx * 3.0, 0.0, 0.0, 3.0},  // on the reject band: not beyond
        {std::nextafter(rx * 3.0, kInf), 0.0, 0.0, 3.0},
        {-std::nextafter(rx * 3.0, kInf), 0.0, 0.0, 3.0},
        {0.0, std::nextafter(ry, kInf), 0.0, 1.0},
        {0.0, -std::nextafter(ry, kInf), 0.0, 1.0},
        {-0.0, 0.0, -0.0, 1.0},
        {1e-320, -1e-320, 0.0, 1.0},  // denormals
        {0.5, 0.25, 0.5, 1e-3},
    };
    // Snapping ties: window x - 0.5 exactly half a subpixel unit off the grid, both signs
    // and both parities; x_window = (x / w * 0.5 + 0.5) * width.
    const double unit = std::ldexp(1.0, -bits);
    for (const double px : {0.5 + 0.5 * unit, 0.5 + 1.5 * unit, 0.5 - 0.5 * unit, 0.5 - 1.5 * unit,
                            100.5 + 2.5 * unit, 0.0, 200.0, -1.0}) {
      const double x_ndc = (px / 200.0 - 0.5) * 2.0;
      clips.emplace_back(x_ndc, x_ndc * 0.5, 0.0, 1.0);
    }
    expectWindowsMatch(clips, setup);
  }
}

// A vertex far enough beyond the viewport that its snapped magnitude passes 2^52 units:
// snapping must return the value itself (roundHalfEven()'s large-magnitude branch), in a
// volume wide enough to call it inside.
TEST(VertexWindows, HugeSnappedMagnitudesKeepTheirValue) {
  WindowSetup setup = setupFor(100, 100, 12);
  setup.volume.guard_x = setup.volume.guard_y = 1e30;
  setup.volume.reject_x = setup.volume.reject_y = 1e30;
  const std::vector<glm::dvec4> clips = {{1e14, -1e14, 0.0, 1.0},
                                         {3e13, 7.0, 0.0, 1.0},
                                         {-2.5e13, -3e13, 0.5, 1.0},
                                         {1.0, 1.0, 0.0, 1.0}};
  expectWindowsMatch(clips, setup);
}

}  // namespace
}  // namespace rc
