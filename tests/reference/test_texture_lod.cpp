// Level of detail against hand-computed answers: the box chain, mirrored repeat, lambda
// from the scale factor with bias and clamps, level selection, the two-level blend and
// magnification, on explicit level-coloured chains rendered through the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "fixtures/mipmaps.h"
#include "reference/reference_renderer.h"
#include "reference/texture_lod.h"
#include "reference/texture_sampling.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

std::shared_ptr<const Texture> solid(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  auto t = std::make_shared<Texture>();
  t->width = w;
  t->height = h;
  for (int i = 0; i < w * h; ++i) t->rgba.insert(t->rgba.end(), {r, g, b, 255});
  return t;
}

// Level k of a 64x64 chain: red, green, blue, yellow, cyan, magenta, white.
constexpr std::uint8_t kLevelColours[7][3] = {{255, 0, 0},    {0, 255, 0},   {0, 0, 255},
                                              {255, 255, 0},  {0, 255, 255}, {255, 0, 255},
                                              {255, 255, 255}};
Material levelMaterial() {
  Material m;
  m.name = "levels";
  m.ambient = glm::dvec3(1.0);
  m.diffuse = glm::dvec3(0.0);
  m.specular = glm::dvec3(0.0);
  m.texture = solid(64, 64, 255, 0, 0);
  for (int k = 1; k < 7; ++k)
    m.texture_levels.push_back(
        solid(64 >> k, 64 >> k, kLevelColours[k][0], kLevelColours[k][1], kLevelColours[k][2]));
  return m;
}

glm::dvec3 level(int k) {
  return glm::dvec3(kLevelColours[k][0], kLevelColours[k][1], kLevelColours[k][2]) / 255.0;
}

// A size x size px square with uv (0, 0)..(1, 1): rho = 64 / size level-0 texels per px.
glm::dvec3 centreColour(int size, MinFilter min, TextureFilter mag, double bias = 0.0,
                        double min_lod = -1000.0, double max_lod = 1000.0) {
  Scene s = test::windowScene(size, size);
  s.state.shading = Shading::Flat;
  s.state.texture_min_filter = min;
  s.state.texture_mag_filter = mag;
  s.state.lod_bias = bias;
  s.state.min_lod = min_lod;
  s.state.max_lod = max_lod;
  const std::size_t m = test::addMaterial(s, levelMaterial());
  test::addRect(s, 0, 0, static_cast<float>(size), static_cast<float>(size), 0.5f, m);
  ReferenceOptions o;
  o.uncertainty = false;
  const Frame f = renderReference(s, o);
  const float* c = &f.color[4 * f.index(size / 2, size / 2)];
  return glm::dvec3(c[0], c[1], c[2]);
}

void expectNear(const glm::dvec3& a, const glm::dvec3& b, const char* what) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-6) << what << " channel " << k;
}

TEST(TextureLod, LambdaIsLog2OfTheScaleFactorWithBiasAndClamps) {
  ref::LodState s;
  EXPECT_DOUBLE_EQ(ref::scaleFactor({3.0, 4.0}, {1.0, 0.0}), 5.0);
  EXPECT_DOUBLE_EQ(ref::lodOf(4.0, s), 2.0);
  s.bias = 0.5;
  EXPECT_DOUBLE_EQ(ref::lodOf(4.0, s), 2.5);
  s.bias = 100.0;  // clamped to kMaxLodBias
  EXPECT_DOUBLE_EQ(ref::lodOf(1.0, s), ref::kMaxLodBias);
  s.bias = 0.0;
  s.min_lod = 1.0;
  s.max_lod = 3.0;
  EXPECT_DOUBLE_EQ(ref::lodOf(1.0, s), 1.0);
  EXPECT_DOUBLE_EQ(ref::lodOf(1024.0, s), 3.0);
  EXPECT_DOUBLE_EQ(ref::lodOf(0.0, s), 1.0);  // log2(0) = -inf, clamped
}

TEST(TextureLod, LevelSelectionAndBlendInARender) {
  // 16 px: rho 4, lambda 2.
  expectNear(centreColour(16, MinFilter::NearestMipmapNearest, TextureFilter::Nearest), level(2),
             "nearest_mipmap_nearest at lambda 2");
  expectNear(centreColour(16, MinFilter::LinearMipmapLinear, TextureFilter::Nearest), level(2),
             "linear_mipmap_linear at lambda 2");
  expectNear(centreColour(16, MinFilter::LinearMipmapLinear, TextureFilter::Nearest, 0.25),
             0.75 * level(2) + 0.25 * level(3), "bias 0.25: a quarter of level 3");
  // nearest_mipmap_nearest rounds: lambda 2.4 -> level 2, 2.6 -> level 3.
  expectNear(centreColour(16, MinFilter::NearestMipmapNearest, TextureFilter::Nearest, 0.4),
             level(2), "lambda 2.4");
  expectNear(centreColour(16, MinFilter::NearestMipmapNearest, TextureFilter::Nearest, 0.6),
             level(3), "lambda 2.6");
  expectNear(centreColour(16, MinFilter::LinearMipmapLinear, TextureFilter::Nearest, 0.0, 3.0),
             level(3), "min_lod 3");
  expectNear(
      centreColour(16, MinFilter::LinearMipmapLinear, TextureFilter::Nearest, 0.0, -1000.0, 1.0),
      level(1), "max_lod 1");
  // Past the last level: level 6 (1x1) alone.
  expectNear(centreColour(16, MinFilter::LinearMipmapLinear, TextureFilter::Nearest, 9.0), level(6),
             "beyond the chain");
  // 128 px: rho 0.5, lambda -1: magnified, level 0 whatever the min filter.
  expectNear(centreColour(128, MinFilter::NearestMipmapLinear, TextureFilter::Linear), level(0),
             "magnified");
  // Non-mipmapped min filters read level 0 when minified.
  expectNear(centreColour(16, MinFilter::Nearest, TextureFilter::Linear), level(0), "nearest");
}

TEST(TextureLod, BoxChainOfOddAndNonSquareSizes) {
  Texture t;
  t.width = 3;
  t.height = 1;
  t.rgba = {0, 10, 200, 255, 9, 20, 100, 255, 255, 255, 255, 255};
  const Texture half = halveTexture(t);
  ASSERT_EQ(half.width, 1);
  ASSERT_EQ(half.height, 1);
  // Texels (0, 0), (1, 0) twice each (the row index clamps): (0 + 9 + 0 + 9 + 2) / 4 = 5.
  EXPECT_EQ(half.rgba[0], 5);
  EXPECT_EQ(half.rgba[1], 15);          // (10 + 20) * 2 + 2 = 62 / 4
  EXPECT_EQ(half.rgba[2], 150);         // (200 + 100) * 2 + 2 = 602 / 4
  EXPECT_EQ(fullMipLevels(45, 27), 6);  // 45, 22, 11, 5, 2, 1
  Material m;
  m.texture = std::make_shared<Texture>(t);
  EXPECT_EQ(mipChain(m).size(), 2u);
  m.texture_levels.push_back(std::make_shared<Texture>(half));
  EXPECT_EQ(mipChain(m).size(), 2u);  // the explicit level replaces the generated one
}

TEST(TextureLod, MirroredRepeatReflectsEveryOtherPeriod) {
  Texture t;
  t.width = 4;
  t.height = 1;
  t.rgba = {0, 0, 0, 255, 80, 0, 0, 255, 160, 0, 0, 255, 240, 0, 0, 255};
  auto red = [&](double u) {
    return ref::sampleTexture(t, {u, 0.5}, TextureFilter::Nearest, TextureWrap::MirroredRepeat).r *
           255.0;
  };
  EXPECT_NEAR(red(0.1), 0.0, 1e-9);    // texel 0
  EXPECT_NEAR(red(1.1), 240.0, 1e-9);  // s 4.4: the mirrored period starts at texel 3
  EXPECT_NEAR(red(1.9), 0.0, 1e-9);    // s 7.6: texel 0 again
  EXPECT_NEAR(red(-0.1), 0.0, 1e-9);   // s -0.4: index -1 mirrors to 0
  EXPECT_NEAR(red(-0.3), 80.0, 1e-9);  // s -1.2: index -2 mirrors to 1
  EXPECT_NEAR(red(2.3), 80.0, 1e-9);   // s 9.2: index 9 = 8 + 1
}

}  // namespace
}  // namespace rc
