// The test-only GL faults (gl_testing.h, RASTERCHECK_GL_FAULT) against an unfaulted
// render of the same scene: each must change exactly what it claims and nothing else,
// so that the harness's self-tests can rely on them as known, located errors.
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "fixtures/loader.h"
#include "gl_backend/gl_testing.h"
#include "tests/gl/gl_test_util.h"
#include "tests/support/printers.h"

namespace rc::gltest {
namespace {

using gl::testing::Faults;
using ::testing::HasSubstr;

constexpr int kSize = 64;  // a power of two: a whole-pixel shift is exact in NDC

// Sets the in-process faults for one scope.
struct FaultScope {
  explicit FaultScope(const Faults& f) { gl::testing::hooks().faults = f; }
  FaultScope(const FaultScope&) = delete;
  FaultScope& operator=(const FaultScope&) = delete;
  ~FaultScope() { gl::testing::hooks() = gl::testing::Hooks{}; }
};

Material lit(const glm::dvec3& kd) {
  Material m;
  m.name = "lit";
  m.ambient = kd;
  m.diffuse = kd;
  m.specular = {0.4, 0.4, 0.4};
  m.shininess = 12.0;
  return m;
}

// No ambient light (colour is linear in the lights), a point and a directional light,
// Phong shading. A back quad (ids 1, 2), a smaller front quad (ids 3, 4) and a sphere
// squashed in y (ids 5...), all at least 8 pixels inside the image, well apart in depth.
Scene faultScene(glm::dvec3 sphere_scale = {0.3, 0.15, 0.3}) {
  Scene s = orthoScene(kSize, kSize);
  s.name = "gltest/faults";
  s.state.shading = Shading::Phong;
  s.ambient_light = glm::dvec3(0.0);
  Light point;
  point.position = {0.5, 0.8, 2.0};
  s.lights.push_back(point);
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = {0.3, -0.4, -1.0};
  sun.intensity = 0.5;
  s.lights.push_back(sun);
  const std::size_t back = addMaterial(s, lit({0.6, 0.5, 0.4}));
  const std::size_t front = addMaterial(s, lit({0.2, 0.5, 0.8}));
  s.objects.push_back(quad(-0.7, -0.7, 0.4, 0.7, -0.5, back));
  s.objects.push_back(quad(-0.5, -0.3, 0.1, 0.5, 0.2, front));
  Object ball;
  ball.name = "ball";
  ball.material = front;
  const int segments = 24, rings = 12;
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::acos(-1.0) * r / rings;
    for (int i = 0; i <= segments; ++i) {
      const double phi = 2.0 * std::acos(-1.0) * i / segments;
      const glm::vec3 p(static_cast<float>(std::sin(theta) * std::cos(phi)),
                        static_cast<float>(std::cos(theta)),
                        static_cast<float>(-std::sin(theta) * std::sin(phi)));
      ball.mesh.positions.push_back(p);
      ball.mesh.normals.push_back(p);
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int i = 0; i < segments; ++i) {
      const auto a = static_cast<std::uint32_t>(r * (segments + 1) + i);
      const auto b = a + static_cast<std::uint32_t>(segments + 1);
      ball.mesh.triangles.push_back({a, b, a + 1});
      ball.mesh.triangles.push_back({a + 1, b, b + 1});
    }
  }
  ball.model = glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 0.3, 0.6)), sphere_scale);
  s.objects.push_back(ball);
  return s;
}

// Pixel ia of a and pixel ib of b have the same colour within tol.
bool sameColorAt(const Frame& a, std::size_t ia, const Frame& b, std::size_t ib, double tol) {
  for (int c = 0; c < 4; ++c) {
    if (std::abs(double(a.color[ia * 4 + c]) - b.color[ib * 4 + c]) > tol) return false;
  }
  return true;
}

bool sameColor(const Frame& a, const Frame& b, std::size_t i, double tol = 0.0) {
  return sameColorAt(a, i, b, i, tol);
}

// The depth slope at pixel i in steps per pixel: the largest difference to a 4-neighbour
// on the same object (ids 1-2, 3-4 and 5+ are the three objects of faultScene).
double slopeSteps(const Frame& f, int x, int y, double steps) {
  auto object = [](std::uint32_t id) { return id == 0 ? 0 : id <= 2 ? 1 : id <= 4 ? 2 : 3; };
  const std::size_t i = f.index(x, y);
  double slope = 0.0;
  for (const auto& [dx, dy] :
       {std::pair{1, 0}, std::pair{0, 1}, std::pair{-1, 0}, std::pair{0, -1}}) {
    const int nx = x + dx, ny = y + dy;
    if (nx < 0 || ny < 0 || nx >= f.width || ny >= f.height) continue;
    const std::size_t j = f.index(nx, ny);
    if (object(f.id[j]) == object(f.id[i]))
      slope = std::max(slope, std::abs(double(f.depth[j]) - f.depth[i]) * steps);
  }
  return slope;
}

// Where the same surface is drawn by slightly different float arithmetic (a shifted
// vertex, gl_FragCoord.z instead of the fixed-function depth), stored depth may move by
// a step plus two subpixel steps of its slope (the agreement tests' rule).
double depthSlack(const Frame& f, int x, int y, double steps) {
  const int bits = f.meta.at("subpixel_bits").get<int>();
  return 1.0 + 2.0 * std::ldexp(1.0, -bits) * slopeSteps(f, x, y, steps);
}

class GlFault : public GlTest {
 protected:
  static Frame renderFaulted(const Scene& s, const Faults& f) {
    FaultScope scope(f);
    return render(s);
  }
};

TEST_F(GlFault, DropPrimitiveRemovesThatTriangleOnly) {
  const Scene s = faultScene();
  const Frame clean = render(s);
  constexpr std::uint32_t kDropped = 3;  // the front quad's first triangle
  Faults f;
  f.drop_primitive = kDropped;
  const Frame faulted = renderFaulted(s, f);
  std::size_t was_there = 0;
  for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
    ASSERT_NE(faulted.id[i], kDropped) << "pixel " << i;
    if (clean.id[i] == kDropped) {
      ++was_there;
      EXPECT_TRUE(faulted.id[i] == 1 || faulted.id[i] == 2) << "the back quad shows through";
      continue;
    }
    EXPECT_EQ(faulted.id[i], clean.id[i]) << "pixel " << i;
    EXPECT_EQ(faulted.depth[i], clean.depth[i]) << "pixel " << i;
    EXPECT_TRUE(sameColor(faulted, clean, i)) << "pixel " << i;
  }
  EXPECT_GT(was_there, 100u);
  EXPECT_EQ(faulted.meta.at("fault_injected"), "drop_primitive=3");
  EXPECT_FALSE(clean.meta.contains("fault_injected"));
}

TEST_F(GlFault, LightScaleScalesEveryLitColour) {
  const Scene s = faultScene();
  const Frame clean = render(s);
  Faults f;
  f.light_scale = 2.0;
  const Frame faulted = renderFaulted(s, f);
  std::size_t lit_pixels = 0;
  for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
    EXPECT_EQ(faulted.id[i], clean.id[i]);
    EXPECT_EQ(faulted.depth[i], clean.depth[i]);
    if (clean.id[i] == 0) {
      EXPECT_TRUE(sameColor(faulted, clean, i));
      continue;
    }
    // No ambient light: every term is linear in the light intensity.
    for (int c = 0; c < 3; ++c) {
      const double want = 2.0 * clean.color[i * 4 + c];
      EXPECT_NEAR(faulted.color[i * 4 + c], want, 1e-5 * std::max(1.0, want)) << "pixel " << i;
    }
    EXPECT_EQ(faulted.color[i * 4 + 3], clean.color[i * 4 + 3]);
    lit_pixels += clean.color[i * 4] > 0.05f ? 1 : 0;
  }
  EXPECT_GT(lit_pixels, 500u);
}

class GlFaultDepth : public GlFault, public ::testing::WithParamInterface<DepthFormat> {};

TEST_P(GlFaultDepth, DepthBiasMovesStoredDepthByWholeSteps) {
  Scene s = faultScene();
  s.state.depth_format = GetParam();
  const Frame clean = render(s);
  constexpr int kSteps = 40;
  Faults f;
  f.depth_bias_steps = kSteps;
  const Frame faulted = renderFaulted(s, f);
  const int bits = depthBits(GetParam());
  const double steps = bits > 0 ? std::ldexp(1.0, bits) - 1.0 : std::ldexp(1.0, 24);
  std::size_t covered = 0, exact = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const std::size_t i = clean.index(x, y);
      ASSERT_EQ(faulted.id[i], clean.id[i]) << "the scene's depths are far apart: ids stay";
      EXPECT_TRUE(sameColor(faulted, clean, i)) << "pixel (" << x << ", " << y << ")";
      if (clean.id[i] == 0) {
        EXPECT_EQ(faulted.depth[i], clean.depth[i]) << "background keeps the clear depth";
        continue;
      }
      ++covered;
      const double moved = (double(faulted.depth[i]) - clean.depth[i]) * steps;
      // gl_FragCoord.z + bias is a float sum, and gl_FragCoord.z is not always the
      // driver's own depth interpolation (softpipe, steep rim of the sphere).
      EXPECT_NEAR(moved, kSteps, depthSlack(clean, x, y, steps))
          << "pixel (" << x << ", " << y << ")";
      exact += std::abs(moved - kSteps) < 0.5 ? 1 : 0;
    }
  }
  EXPECT_GT(covered, 1000u);
  EXPECT_GT(exact, covered * 9 / 10) << "most pixels move by exactly " << kSteps << " steps";
}

INSTANTIATE_TEST_SUITE_P(Formats, GlFaultDepth,
                         ::testing::Values(DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F),
                         [](const auto& p) { return std::string(toString(p.param)); });

TEST_F(GlFault, NoInverseTransposeChangesOnlyNonUniformlyScaledNormals) {
  Faults f;
  f.no_inverse_transpose = true;
  // Squashed sphere: its normals are wrong under the fault; the quads (identity model)
  // are not touched.
  {
    const Scene s = faultScene({0.3, 0.15, 0.3});
    const Frame clean = render(s);
    const Frame faulted = renderFaulted(s, f);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
      ASSERT_EQ(faulted.id[i], clean.id[i]);
      EXPECT_EQ(faulted.depth[i], clean.depth[i]);
      if (clean.id[i] <= 4) {
        EXPECT_TRUE(sameColor(faulted, clean, i)) << "pixel " << i;
      } else if (!sameColor(faulted, clean, i, 0.01)) {
        ++changed;
      }
    }
    EXPECT_GT(changed, 50u) << "the squashed sphere's shading must change";
  }
  // Uniform scale: model matrix and inverse transpose give the same unit normals.
  {
    const Scene s = faultScene({0.3, 0.3, 0.3});
    const Frame clean = render(s);
    const Frame faulted = renderFaulted(s, f);
    for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
      ASSERT_EQ(faulted.id[i], clean.id[i]);
      EXPECT_TRUE(sameColor(faulted, clean, i, 1e-5)) << "pixel " << i;
    }
  }
}

TEST_F(GlFault, ShiftXMovesTheImageRight) {
  const Scene s = faultScene();
  const Frame clean = render(s);
  constexpr int kShift = 5;
  Faults f;
  f.shift_x_px = kShift;
  const Frame faulted = renderFaulted(s, f);
  std::size_t covered = 0, same_depth = 0;
  double max_dz = 0.0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const std::size_t moved = faulted.index(x, y);
      if (x < kShift) {
        EXPECT_EQ(faulted.id[moved], 0u) << "nothing was left of x = 8 before the shift";
        continue;
      }
      const std::size_t i = clean.index(x - kShift, y);
      ASSERT_EQ(faulted.id[moved], clean.id[i]) << "pixel (" << x << ", " << y << ")";
      // Shifted vertices round (and snap) differently in float: on the sphere's steep rim
      // that moves the depth plane by a few steps.
      const double dz = std::abs(double(faulted.depth[moved]) - clean.depth[i]) * 16777215.0;
      max_dz = std::max(max_dz, dz);
      EXPECT_LE(dz, depthSlack(clean, x - kShift, y, 16777215.0))
          << "pixel (" << x << ", " << y << ")";
      same_depth += dz == 0.0 ? 1 : 0;
      // Shading uses world positions, which the window-space shift does not touch.
      EXPECT_TRUE(sameColorAt(faulted, moved, clean, i, 1e-5))
          << "pixel (" << x << ", " << y << ")";
      covered += clean.id[i] != 0 ? 1 : 0;
    }
  }
  EXPECT_GT(covered, 1000u);
  EXPECT_GT(same_depth, (kSize - kShift) * kSize * 9 / 10) << "max " << max_dz << " steps";
}

TEST_F(GlFault, MoveVertexMovesOneVertexOfOneTriangle) {
  const Scene s = faultScene();
  const Frame clean = render(s);
  constexpr std::uint32_t kMoved = 3;  // the front quad's first triangle (0, 1, 2)
  Faults f;
  f.move_vertex = kMoved;
  const Frame faulted = renderFaulted(s, f);
  EXPECT_EQ(faulted.meta.at("fault_injected"), "move_vertex=3");
  std::size_t changed = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const std::size_t i = clean.index(x, y);
      if (faulted.id[i] == clean.id[i]) {
        if (clean.id[i] != kMoved) {
          EXPECT_EQ(faulted.depth[i], clean.depth[i]) << "pixel (" << x << ", " << y << ")";
          EXPECT_TRUE(sameColor(faulted, clean, i)) << "pixel (" << x << ", " << y << ")";
        }
        continue;
      }
      ++changed;
      EXPECT_TRUE(clean.id[i] == kMoved || faulted.id[i] == kMoved)
          << "pixel (" << x << ", " << y << "): " << clean.id[i] << " -> " << faulted.id[i]
          << ": only triangle 3 may change";
      // The corner (-0.5, -0.3) is at image (16, 41.6); moving it one pixel right along
      // the quad's bottom edge opens a sliver between triangle 3's new edge and
      // triangle 4's diagonal (to the corner (0.1, 0.5), image (35.2, 16)): only there.
      EXPECT_TRUE(x >= 15 && x <= 36 && y >= 15 && y <= 42) << "pixel (" << x << ", " << y << ")";
    }
  }
  // The sliver: 1 px wide at the corner, tapering over the 25.6 px height of the
  // diagonal, about 13 px; far from the ~250 px of the whole triangle.
  EXPECT_GT(changed, 5u);
  EXPECT_LT(changed, 40u);
}

// A full-image quad with an 8x8 texture of distinct texels (8 px each), nearest, repeat,
// lit by ambient light only: each pixel shows its texel's colour.
Scene texelScene() {
  Scene s = orthoScene(kSize, kSize);
  s.name = "gltest/texels";
  s.ambient_light = glm::dvec3(1.0);
  auto texture = std::make_shared<Texture>();
  texture->path = "generated-8x8";
  texture->width = 8;
  texture->height = 8;
  for (int t = 0; t < 64; ++t) {
    texture->rgba.insert(texture->rgba.end(),
                         {static_cast<std::uint8_t>(t * 4), static_cast<std::uint8_t>(255 - t * 3),
                          static_cast<std::uint8_t>((t * 37) % 256), 255});
  }
  Material m = lit({1.0, 1.0, 1.0});
  m.diffuse = glm::dvec3(0.0);
  m.specular = glm::dvec3(0.0);
  m.texture = texture;
  const std::size_t mat = addMaterial(s, m);
  s.objects.push_back(quad(-1.0, -1.0, 1.0, 1.0, 0.0, mat));
  return s;
}

TEST_F(GlFault, TexelOffsetSamplesTheNeighbouringTexel) {
  const Scene s = texelScene();
  const Frame clean = render(s);
  Faults f;
  f.texel_offset = 1.0;
  const Frame faulted = renderFaulted(s, f);
  EXPECT_EQ(faulted.meta.at("fault_injected"), "texel_offset=1");
  constexpr int kTexelPx = kSize / 8;
  std::size_t differs = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const std::size_t i = clean.index(x, y);
      ASSERT_EQ(faulted.id[i], clean.id[i]);
      EXPECT_EQ(faulted.depth[i], clean.depth[i]);
      // The texel to the right (repeat wraps the last column to the first) is what the
      // clean image shows one texel width further right.
      const std::size_t right = clean.index((x + kTexelPx) % kSize, y);
      EXPECT_TRUE(sameColorAt(faulted, i, clean, right, 1e-6))
          << "pixel (" << x << ", " << y << ")";
      differs += sameColor(faulted, clean, i, 1e-3) ? 0 : 1;
    }
  }
  EXPECT_EQ(differs, clean.pixelCount()) << "every texel differs from its right neighbour";
}

// A full-image quad whose texture has one colour per mip level (level 0 128x128 for 64
// pixels: lambda = 1 everywhere, face-on), ambient light only.
Scene levelScene(MinFilter min, double lod_bias) {
  Scene s = texelScene();
  s.name = "gltest/levels";
  auto solid = [](int size, std::array<std::uint8_t, 3> rgb) {
    auto t = std::make_shared<Texture>();
    t->path = fmt::format("generated-{}x{}", size, size);
    t->width = t->height = size;
    for (int i = 0; i < size * size; ++i)
      t->rgba.insert(t->rgba.end(), {rgb[0], rgb[1], rgb[2], 255});
    return t;
  };
  Material& m = s.materials.back();
  m.texture = solid(128, {255, 0, 0});
  m.texture_levels = {solid(64, {0, 255, 0}), solid(32, {0, 0, 255})};
  for (int size = 16; size >= 1; size /= 2)
    m.texture_levels.push_back(solid(size, {255, 255, 255}));
  s.state.texture_min_filter = min;
  s.state.lod_bias = lod_bias;
  return s;
}

TEST_F(GlFault, LodWeightInvertsTheBlendBetweenLevelsOnly) {
  Faults f;
  f.lod_weight_inverted = true;
  // lambda = 1.25: level 1 (green) weighted 0.75 and level 2 (blue) 0.25; the fault swaps
  // the weights. Filtering within a level of one colour changes nothing.
  const Scene blended = levelScene(MinFilter::LinearMipmapLinear, 0.25);
  const Frame clean = render(blended);
  const Frame faulted = renderFaulted(blended, f);
  EXPECT_EQ(faulted.meta.at("fault_injected"), "lod_weight=inverted");
  constexpr double kTol = 0.02;  // the driver's own lambda and weight precision
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const glm::dvec4 c = colorAt(clean, x, y), d = colorAt(faulted, x, y);
      ASSERT_NEAR(c.g, 0.75, kTol) << x << "," << y;
      ASSERT_NEAR(c.b, 0.25, kTol) << x << "," << y;
      ASSERT_NEAR(d.g, 0.25, kTol) << x << "," << y;
      ASSERT_NEAR(d.b, 0.75, kTol) << x << "," << y;
      ASSERT_NEAR(d.r, 0.0, kTol) << x << "," << y;
    }
  }
  // One level at a time (nearest between levels): nothing to weigh, nothing changes.
  const Scene one_level = levelScene(MinFilter::LinearMipmapNearest, 0.25);
  EXPECT_EQ(render(one_level).color, renderFaulted(one_level, f).color);
}

// The shadow faults act on the frame pass's lookups only: ids, depth and the shadow map
// itself stay the same bits; colours change, and only where light 0 reaches (the ambient
// term is never shadowed), never below the ambient-only colour of the lit surfaces.
TEST_F(GlFault, ShadowFaultsChangeOnlyTheLookups) {
  const Scene s = loadScene(std::filesystem::path(RC_SOURCE_DIR) /
                            "fixtures/scenes/shadow/teapot_on_plane.json");
  const Frame clean = render(s);
  ASSERT_EQ(clean.passes.size(), 1u);
  EXPECT_EQ(clean.passes[0].meta.at("pass").at("target"), "sun");
  Faults shift;
  shift.shadow_shift = 1.0;
  Faults inverted;
  inverted.shadow_compare_inverted = true;
  Faults dropped;
  dropped.shadow_bias_dropped = true;
  for (const Faults& f : {shift, inverted, dropped}) {
    const Frame faulted = renderFaulted(s, f);
    EXPECT_EQ(faulted.meta.at("fault_injected"), f.describe());
    EXPECT_EQ(faulted.id, clean.id) << f.describe();
    EXPECT_EQ(faulted.depth, clean.depth) << f.describe();
    ASSERT_EQ(faulted.passes.size(), 1u);
    EXPECT_EQ(faulted.passes[0].depth, clean.passes[0].depth) << f.describe();
    std::size_t changed = 0;
    for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
      if (sameColor(faulted, clean, i, 1e-6)) continue;
      ++changed;
      EXPECT_NE(clean.id[i], 0u) << f.describe() << ": background changed at " << i;
    }
    // The map moved by a texel and the comparison turned round change hundreds of pixels
    // of this scene; without its bias, acne appears where the floor faces the light most
    // obliquely (a dozen pixels or more).
    EXPECT_GT(changed, f.shadow_bias_dropped ? 10u : 100u) << f.describe();
  }
}

class GlFaultBlend : public GlFault, public ::testing::WithParamInterface<Faults::Blend> {};

TEST_P(GlFaultBlend, WrongBlendFactorChangesOnlyBlendedPixels) {
  Scene s = faultScene();
  s.state.blend = Blend::Alpha;
  s.materials[1].opacity = 0.3;  // the front quad and the ball
  const Frame clean = render(s);
  Faults f;
  f.blend_factor = GetParam();
  const Frame faulted = renderFaulted(s, f);
  std::size_t blended = 0;
  for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
    ASSERT_EQ(faulted.id[i], clean.id[i]);
    EXPECT_EQ(faulted.depth[i], clean.depth[i]);
    if (clean.id[i] <= 2) {
      EXPECT_TRUE(sameColor(faulted, clean, i)) << "opaque or background pixel " << i;
      continue;
    }
    // src*1 + dst*(1-a) differs from src*a + dst*(1-a) wherever the transparent fragment
    // has colour; src*(1-a) + dst*a wherever src and dst differ (not at a = 0.5, hence 0.3).
    if (!sameColor(faulted, clean, i, 1e-3)) ++blended;
  }
  EXPECT_GT(blended, 300u);
}

INSTANTIATE_TEST_SUITE_P(Factors, GlFaultBlend,
                         ::testing::Values(Faults::Blend::One, Faults::Blend::Swapped),
                         [](const auto& p) {
                           return std::string(p.param == Faults::Blend::One ? "one" : "swapped");
                         });

TEST_F(GlFault, ShaderCompileErrorIsABackendErrorWithTheLog) {
  Faults f;
  f.shader_compile_error = true;
  FaultScope scope(f);
  try {
    render(faultScene());
    FAIL() << "the broken shader compiled";
  } catch (const BackendError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("gltest/faults: "));
    EXPECT_THAT(std::string(e.what()), HasSubstr("fragment shader does not compile"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("rc_injected_compile_error"));
  }
}

// The environment variable reaches renderGl (what a child `rastercheck render` sees).
TEST_F(GlFault, EnvironmentVariableInjectsAndIsRecorded) {
  const Scene s = faultScene();
  const Frame clean = render(s);
  ASSERT_EQ(setenv(gl::testing::kFaultVariable, "light_scale=0", 1), 0);
  Frame faulted;
  try {
    faulted = render(s);
  } catch (...) {
    unsetenv(gl::testing::kFaultVariable);
    throw;
  }
  unsetenv(gl::testing::kFaultVariable);
  EXPECT_EQ(faulted.meta.at("fault_injected"), "light_scale=0");
  for (std::size_t i = 0; i < clean.pixelCount(); ++i) {
    if (clean.id[i] == 0) continue;
    EXPECT_EQ(faulted.color[i * 4], 0.0f) << "no light, no ambient: black";
  }
}

TEST(GlFaultParse, CanonicalFormRoundTrips) {
  const Faults f = gl::testing::parseFaults(
      "shift_x=2.5,drop_primitive=12,,no_inverse_transpose,depth_bias=-3,light_scale=0.5");
  EXPECT_EQ(f.drop_primitive, 12u);
  EXPECT_EQ(f.depth_bias_steps, -3);
  EXPECT_EQ(f.light_scale, 0.5);
  EXPECT_TRUE(f.no_inverse_transpose);
  EXPECT_EQ(f.shift_x_px, 2.5);
  EXPECT_FALSE(f.shader_compile_error);
  const std::string text = f.describe();
  EXPECT_EQ(text,
            "drop_primitive=12,depth_bias=-3,light_scale=0.5,no_inverse_transpose,shift_x=2.5");
  const Faults more = gl::testing::parseFaults("blend_factor=swapped,texel_offset=1,move_vertex=7");
  EXPECT_EQ(more.move_vertex, 7u);
  EXPECT_EQ(more.texel_offset, 1.0);
  EXPECT_EQ(more.blend_factor, Faults::Blend::Swapped);
  EXPECT_EQ(more.describe(), "move_vertex=7,texel_offset=1,blend_factor=swapped");
  EXPECT_EQ(gl::testing::parseFaults("blend_factor=one").describe(), "blend_factor=one");
  const Faults lod = gl::testing::parseFaults("lod_weight=inverted,lod_shift=1");
  EXPECT_TRUE(lod.lod_weight_inverted);
  EXPECT_EQ(lod.describe(), "lod_shift=1,lod_weight=inverted");
  EXPECT_THROW(gl::testing::parseFaults("lod_weight=swapped"), InputError);
  const Faults shadow =
      gl::testing::parseFaults("shadow_bias=dropped,shadow_compare=inverted,shadow_shift=2");
  EXPECT_EQ(shadow.shadow_shift, 2.0);
  EXPECT_TRUE(shadow.shadow_compare_inverted);
  EXPECT_TRUE(shadow.shadow_bias_dropped);
  EXPECT_EQ(shadow.describe(), "shadow_shift=2,shadow_compare=inverted,shadow_bias=dropped");
  EXPECT_THROW(gl::testing::parseFaults("shadow_bias=kept"), InputError);
  EXPECT_THROW(gl::testing::parseFaults("shadow_compare=swapped"), InputError);
  const Faults again = gl::testing::parseFaults(text);
  EXPECT_EQ(again.describe(), text);
  EXPECT_FALSE(gl::testing::parseFaults("").any());
}

TEST(GlFaultParse, HangAndCrashNameTheFixtureTheyHit) {
  const Faults f = gl::testing::parseFaults("hang=coverage/triangle_fan,crash=*");
  EXPECT_TRUE(f.any());
  EXPECT_TRUE(f.hangs("coverage/triangle_fan"));
  EXPECT_FALSE(f.hangs("coverage/other"));
  EXPECT_TRUE(f.crashes("anything"));
  EXPECT_EQ(f.describe(), "hang=coverage/triangle_fan,crash=*");
  EXPECT_EQ(gl::testing::parseFaults(f.describe()).describe(), f.describe());
  const Faults none = gl::testing::parseFaults("light_scale=2");
  EXPECT_FALSE(none.hangs("x"));
  EXPECT_FALSE(none.crashes("x"));
}

TEST(GlFaultParse, BadEntriesAreInputErrorsNamingTheVariable) {
  for (const char* bad :
       {"frobnicate", "drop_primitive", "drop_primitive=0", "drop_primitive=x", "depth_bias=1.5",
        "light_scale=nan", "light_scale=", "no_inverse_transpose=1", "shift_x=inf",
        "shader_compile_error=yes", "light_scale=2,bogus=1", "move_vertex=0", "move_vertex",
        "texel_offset=x", "blend_factor=zero", "blend_factor", "hang", "hang=", "crash"}) {
    try {
      gl::testing::parseFaults(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_THAT(std::string(e.what()), HasSubstr("RASTERCHECK_GL_FAULT")) << bad;
    }
  }
}

}  // namespace
}  // namespace rc::gltest
