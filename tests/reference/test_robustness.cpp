// Bad input never crashes: NaN/Inf/enormous vertices, empty meshes, 1x1 and 4096x4096
// images, degenerate cameras; invalid options and inconsistent scenes are InputErrors.
// Also the pixel trace (rastercheck explain).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "fixtures/errors.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(Robustness, NonFiniteTrianglesAreDroppedOthersDrawn) {
  Scene s = test::windowScene(16, 16);
  test::addTriangle(s, {kNaN, 1, 0.5f}, {15, 1, 0.5f}, {1, 15, 0.5f});  // id 1
  test::addTriangle(s, {1, 1, kInf}, {15, 1, 0.5f}, {1, 15, 0.5f});     // id 2
  test::addTriangle(s, {1, 1, 0.5f}, {-kInf, 1, 0.5f}, {1, 15, 0.5f});  // id 3
  test::addTriangle(s, {1, 1, 0.75f}, {15, 1, 0.75f}, {1, 15, 0.75f});  // id 4: valid
  s.objects[0].mesh.normals[1] = {kNaN, 0, 0};
  for (Shading sh : {Shading::Flat, Shading::Gouraud, Shading::Phong}) {
    s.state.shading = sh;
    const Frame f = renderReference(s);
    int drawn = 0;
    for (std::uint32_t id : f.id) {
      EXPECT_TRUE(id == 0u || id == 4u) << id;
      drawn += id == 4u;
    }
    EXPECT_GT(drawn, 50);
  }
}

TEST(Robustness, EnormousButFiniteCoordinates) {
  // 1e12 px: clipping against the guard band still places the cut within a small
  // fraction of a subpixel, so coverage is exact.
  Scene s = test::windowScene(16, 16);
  test::addTriangle(s, {-1e12f, -1e12f, 0.5f}, {1e12f, -1e12f, 0.5f}, {0, 1e12f, 0.5f});
  Frame f = renderReference(s);
  for (std::uint32_t id : f.id) EXPECT_EQ(id, 1u);
  // Near the float limit double precision cannot place a guard-band cut to the pixel
  // (|A - B| * 2^-53 is still ~1e21 clip units): no crash, sane values, nothing else.
  Scene huge = test::windowScene(16, 16);
  test::addTriangle(huge, {-1e30f, -1e30f, 0.5f}, {1e30f, -1e30f, 0.5f}, {0, 1e30f, 0.5f});
  test::addTriangle(huge, {-3e38f, 0, 0.5f}, {3e38f, 0, 0.25f}, {0, 3e38f, 0.6f});
  f = renderReference(huge);
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    EXPECT_LE(f.id[i], 2u);
    EXPECT_TRUE(f.depth[i] >= 0.0f && f.depth[i] <= 1.0f);
    EXPECT_TRUE(std::isfinite(f.color[4 * i]));
  }
  Scene p;  // perspective, vertices at the float limit, some behind the camera
  p.width = 8;
  p.height = 8;
  p.materials.push_back(Material{});
  test::addTriangle(p, {-3e38f, -3e38f, -1}, {3e38f, -3e38f, 3e38f}, {0, 3e38f, -3e38f});
  EXPECT_NO_THROW(renderReference(p));
}

TEST(Robustness, EmptyMeshesAndEmptyScenes) {
  Scene s = test::windowScene(8, 8);
  s.clear_depth = 0.5;
  s.objects.emplace_back();                            // no vertices, no triangles
  test::addMesh(s, {{0, 0, 0.5f}, {1, 0, 0.5f}}, {});  // vertices, no triangles
  const Frame f = renderReference(s);
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    EXPECT_EQ(f.id[i], 0u);
    EXPECT_EQ(f.depth[i], static_cast<float>(8388608.0 / 16777215.0));  // 0.5 stored in d24
    EXPECT_EQ(f.depth_gap[i], std::numeric_limits<float>::infinity());
    EXPECT_EQ(f.edge_dist[i], 1.0f);
  }
  s.objects.clear();
  EXPECT_NO_THROW(renderReference(s));
}

TEST(Robustness, DegenerateAndNonFiniteLinesAndPoints) {
  // A zero-length segment draws nothing (its end lies in its start's diamond); a loop of one
  // position has one zero-length segment; non-finite and enormous ends are dropped or
  // clipped; a point far outside marks nothing but its own neighbourhood; wide everything.
  Scene s = test::windowScene(32, 24);
  s.state.shading = Shading::Phong;
  s.state.ops.line_width = 7.0;
  s.state.ops.point_size = 64.0;
  auto add = [&](PrimitiveKind kind, std::vector<glm::vec3> positions,
                 std::vector<std::array<std::uint32_t, 2>> lines) {
    Object o;
    o.primitive = kind;
    o.mesh.positions = std::move(positions);
    o.mesh.normals.assign(o.mesh.positions.size(), glm::vec3(0, 0, 1));
    o.mesh.lines = std::move(lines);
    s.objects.push_back(std::move(o));
  };
  add(PrimitiveKind::Lines, {{10.3f, 10.2f, 0.5f}}, {{0, 0}});                  // id 1
  add(PrimitiveKind::Lines, {{kNaN, 1, 0.5f}, {30, 20, 0.5f}}, {{0, 1}});       // id 2
  add(PrimitiveKind::Lines, {{-3e38f, 1e38f, 0.5f}, {20, 5, 0.5f}}, {{0, 1}});  // id 3
  add(PrimitiveKind::Points, {{3e38f, 1e38f, 0.5f}, {16, 12, kInf}}, {});       // 4, 5
  add(PrimitiveKind::Lines, {}, {});                                            // empty
  const Frame f = renderReference(s);
  int drawn_segment = 0;
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    EXPECT_TRUE(f.id[i] == 0u || f.id[i] == 3u) << f.id[i];
    drawn_segment += f.id[i] == 3u;
    EXPECT_TRUE(f.depth[i] >= 0.0f && f.depth[i] <= 1.0f);
    EXPECT_TRUE(std::isfinite(f.color[4 * i]));
  }
  EXPECT_GT(drawn_segment, 20) << "the clipped huge segment still crosses the window";
  // The same, traced at a pixel of it: no crash, the fragments of id 3 only.
  const std::vector<FragmentTrace> trace = tracePixel(s, ReferenceOptions{}, 16, 16);
  for (const FragmentTrace& t : trace) EXPECT_EQ(t.primitive, 3u);
}

TEST(Robustness, OneByOneImage) {
  Scene s = test::windowScene(1, 1);
  test::addTriangle(s, {-1, -1, 0.5f}, {3, -1, 0.5f}, {-1, 3, 0.5f});
  const Frame f = renderReference(s);
  ASSERT_EQ(f.pixelCount(), 1u);
  EXPECT_EQ(f.id[0], 1u);
  Scene p;
  p.width = 1;
  p.height = 1;
  p.materials.push_back(Material{});
  test::addTriangle(p, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
  EXPECT_EQ(renderReference(p).id[0], 1u);
}

TEST(Robustness, LargeImage4096) {
  Scene s = test::windowScene(4096, 4096);
  test::addRect(s, -1, -1, 4097, 4097, 0.5f);
  const auto start = std::chrono::steady_clock::now();
  const Frame f = renderReference(s);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(f.pixelCount(), 4096u * 4096u);
  for (std::size_t i = 0; i < f.pixelCount(); i += 4099) ASSERT_NE(f.id[i], 0u);
  EXPECT_EQ(f.id[f.index(4095, 4095)] != 0u, true);
  RecordProperty("seconds", std::to_string(seconds));
}

TEST(Robustness, DegenerateCamerasDoNotCrash) {
  for (int variant = 0; variant < 4; ++variant) {
    Scene s;
    s.width = 8;
    s.height = 8;
    s.materials.push_back(Material{});
    if (variant == 0) s.camera.near = 0.0;
    if (variant == 1) s.camera.fovy_deg = 0.0;
    if (variant == 2) s.camera.eye = s.camera.target;  // zero view direction
    if (variant == 3) s.camera.far = s.camera.near;
    test::addTriangle(s, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
    EXPECT_NO_THROW(renderReference(s)) << variant;
  }
}

TEST(Robustness, InvalidOptionsAndScenesAreInputErrors) {
  Scene s = test::windowScene(8, 8);
  test::addRect(s, 0, 0, 8, 8, 0.5f);
  EXPECT_THROW(renderReference(s, ReferenceOptions{-1, false, true}), InputError);
  EXPECT_THROW(renderReference(s, ReferenceOptions{13, false, true}), InputError);
  EXPECT_NO_THROW(renderReference(s, ReferenceOptions{0, false, true}));
  EXPECT_NO_THROW(renderReference(s, ReferenceOptions{12, false, true}));
  for (auto [w, h] : {std::pair{0, 8}, {8, -5}, {20000, 8}, {16384, 4097}}) {
    Scene bad = s;
    bad.width = w;
    bad.height = h;
    EXPECT_THROW(renderReference(bad), InputError) << w << "x" << h;
  }
  Scene bad = s;
  bad.objects[0].material = 5;
  EXPECT_THROW(renderReference(bad), InputError);
  bad = s;
  bad.objects[0].mesh.normals.pop_back();
  EXPECT_THROW(renderReference(bad), InputError);
  bad = s;
  bad.objects[0].mesh.uvs.pop_back();
  EXPECT_THROW(renderReference(bad), InputError);
  bad = s;
  bad.objects[0].mesh.triangles[1][2] = 4;
  try {
    renderReference(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("objects[0]"), std::string::npos) << e.what();
  }
  bad = s;
  auto t = std::make_shared<Texture>();
  t->width = 2;
  t->height = 2;
  t->rgba = {1, 2, 3};
  bad.materials[0].texture = t;
  EXPECT_THROW(renderReference(bad), InputError);
  EXPECT_THROW(tracePixel(s, {}, 8, 0), InputError);
  EXPECT_THROW(tracePixel(s, {}, 0, -1), InputError);
}

TEST(Robustness, TextureWithoutUvsSamplesTheBottomLeftTexel) {
  Scene s = test::windowScene(4, 4);
  auto t = std::make_shared<Texture>();
  t->width = 2;
  t->height = 2;
  t->rgba = {10, 20, 30, 255, 40, 50, 60, 255, 70, 80, 90, 255, 100, 110, 120, 255};
  s.materials[0].texture = t;
  test::addMesh(s, {{-1, -1, 0.5f}, {9, -1, 0.5f}, {-1, 9, 0.5f}}, {{0, 1, 2}});
  const Frame f = renderReference(s);
  EXPECT_FLOAT_EQ(f.color[4 * f.index(2, 2)], 10.0f / 255);
}

// ---- the pixel trace -------------------------------------------------------------------------

TEST(Trace, EveryFragmentInDrawOrderWithItsDepthTest) {
  Scene s = test::windowScene(8, 8);
  s.materials = {s.materials[0], s.materials[0], s.materials[0]};
  s.materials[1].ambient = {0, 1, 0};
  s.materials[2].ambient = {0, 0, 1};
  test::addRect(s, 0, 0, 8, 8, 0.5f, 0);   // ids 1, 2: window depth 0.5
  test::addRect(s, 0, 0, 8, 8, 0.75f, 1);  // ids 3, 4: nearer (0.25), passes
  test::addRect(s, 0, 0, 8, 8, 0.25f, 2);  // ids 5, 6: farther (0.75), fails
  const Frame f = renderReference(s);
  const auto trace = tracePixel(s, {}, 2, 5);
  ASSERT_EQ(trace.size(), 3u);
  EXPECT_TRUE(trace[0].primitive == 1u || trace[0].primitive == 2u);
  EXPECT_TRUE(trace[1].primitive == 3u || trace[1].primitive == 4u);
  EXPECT_TRUE(trace[2].primitive == 5u || trace[2].primitive == 6u);
  EXPECT_EQ(trace[1].object, 1u);
  EXPECT_TRUE(trace[0].depth_pass);
  EXPECT_EQ(trace[0].depth_against, 1.0);  // the clear depth
  EXPECT_TRUE(trace[1].depth_pass);
  EXPECT_EQ(trace[1].depth_against, trace[0].stored_z);
  EXPECT_FALSE(trace[2].depth_pass);
  EXPECT_EQ(trace[2].depth_against, trace[1].stored_z);
  EXPECT_DOUBLE_EQ(trace[1].window_z, 0.25);
  EXPECT_EQ(trace[1].stored_z, 4194304.0 / 16777215.0);
  EXPECT_EQ(trace[2].color_written, trace[1].color_written);  // failed: unchanged
  EXPECT_EQ(trace[2].shading.color, glm::dvec4(0, 0, 1, 1));  // shaded anyway
  EXPECT_EQ(trace[1].color_written, glm::dvec4(0, 1, 0, 1));
  for (const FragmentTrace& t : trace)
    EXPECT_NEAR(t.barycentric.x + t.barycentric.y + t.barycentric.z, 1.0, 1e-12);
  const float* c = &f.color[4 * f.index(2, 5)];
  EXPECT_EQ(trace.back().color_written, glm::dvec4(c[0], c[1], c[2], c[3]));
  EXPECT_EQ(trace.back().primitive == 5u || trace.back().primitive == 6u, true);
  EXPECT_TRUE(tracePixel(test::windowScene(8, 8), {}, 3, 3).empty());
}

TEST(Trace, MatchesTheFrameOnEveryPixelOfAFeatureScene) {
  for (const auto& [name, scene] : test::featureScenes()) {
    if (name != "lit_gouraud" && name != "lit_phong_rgba8_d16_cull") continue;
    const Frame f = renderReference(scene);
    for (int y = 0; y < scene.height; y += 5)
      for (int x = 0; x < scene.width; x += 3) {
        const auto trace = tracePixel(scene, {}, x, y);
        const std::size_t i = f.index(x, y);
        const float* c = &f.color[4 * i];
        const glm::dvec4 frame_color(c[0], c[1], c[2], c[3]);
        if (trace.empty()) {
          EXPECT_EQ(f.id[i], 0u);
          continue;
        }
        // The last fragment that passed wrote the id; the last one's colour is the frame's.
        std::uint32_t id = 0;
        for (const FragmentTrace& t : trace)
          if (t.depth_pass) id = t.primitive;
        EXPECT_EQ(f.id[i], id) << name << " " << x << "," << y;
        EXPECT_EQ(glm::dvec4(glm::vec4(trace.back().color_written)), frame_color)
            << name << " " << x << "," << y;
        // Shading terms add up to the colour.
        for (const FragmentTrace& t : trace) {
          glm::dvec3 ad = t.shading.ambient, sp(0.0);
          for (const LightTerms& l : t.shading.lights) {
            ad += l.diffuse;
            sp += l.specular;
          }
          const glm::dvec3 rgb = ad * t.shading.texture + sp;
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(t.shading.color[k], rgb[k], 1e-12);
        }
      }
  }
}

}  // namespace
}  // namespace rc
