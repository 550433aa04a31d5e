// Visibility modes and framebuffer formats against hand-computed results: painter's
// algorithm, the transparent pass, rgba8 rounding.
#include <gtest/gtest.h>

#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

Material flatColor(const glm::dvec3& c, double opacity = 1.0) {
  Material m;
  m.ambient = c;
  m.diffuse = glm::dvec3(0.0);
  m.specular = glm::dvec3(0.0);
  m.opacity = opacity;
  return m;
}

glm::dvec4 colorAt(const Frame& f, int x, int y) {
  const float* c = &f.color[4 * f.index(x, y)];
  return glm::dvec4(c[0], c[1], c[2], c[3]);
}

// Object 0: a plane tilted in y (window depth 1 - z with z = 0.9 - 0.8 (y + 16) / 64,
// nearer than object 1 below y = 8, farther above), mean view depth 0.367.
// Object 1: a flat rectangle at window depth 0.4 (mean view depth 0.4).
Scene painterScene() {
  Scene s = test::windowScene(16, 16);
  test::addTriangle(s, {-16, -16, 0.9f}, {48, -16, 0.9f}, {-16, 48, 0.1f});
  test::addRect(s, -1, -1, 17, 17, 0.6f);
  return s;
}

TEST(Visibility, ZBufferPainterAndNoDepthTest) {
  Scene s = painterScene();
  const Frame z = renderReference(s);
  for (int y = 0; y < 16; ++y) {
    const int gl_row = 15 - y;  // centre gl_row + 0.5 < 8: the tilted plane is nearer
    const std::uint32_t id = z.id[z.index(5, y)];  // 1: the plane; 2, 3: the rectangle
    EXPECT_EQ(id == 1u, gl_row < 8) << "zbuffer row " << gl_row << " id " << id;
    EXPECT_NE(id, 0u);
  }
  // Painter's: sorted far-to-near by mean view depth, the rectangle (0.4) is drawn first,
  // the tilted plane (0.367) over it: the plane everywhere, whatever the depths.
  s.state.visibility = Visibility::Painter;
  const Frame p = renderReference(s);
  for (std::uint32_t id : p.id) EXPECT_EQ(id, 1u);
  // Depth is written by every fragment (ALWAYS): the plane's depth at the top row.
  EXPECT_NEAR(p.depth[p.index(5, 0)], 1.0 - (0.9 - 0.8 * 31.5 / 64), 1e-7);
  // ref:painter forces it on a z-buffer scene.
  s.state.visibility = Visibility::ZBuffer;
  const Frame forced = renderReference(s, ReferenceOptions{8, true, true});
  EXPECT_EQ(forced.id, p.id);
  EXPECT_EQ(forced.meta["painter_forced"], true);
  // No depth test: file order, the last drawn (the rectangle, ids 2-3) wins.
  s.state.depth_test = false;
  const Frame a = renderReference(s);
  for (std::uint32_t id : a.id) EXPECT_TRUE(id == 2u || id == 3u);
}

// Left half: opaque red (window depth 0.75) under transparent green (0.4) and blue (0.2),
// listed blue-before-green in the file; right half: transparent green behind the red.
Scene alphaScene(ColorFormat format) {
  Scene s = test::windowScene(8, 8);
  s.state.blend = Blend::Alpha;
  s.state.color_format = format;
  s.materials = {flatColor({1, 0, 0}), flatColor({0, 1, 0}, 0.5), flatColor({0, 0, 1}, 0.5)};
  test::addRect(s, 0, 0, 4, 8, 0.8f, 2);   // blue, nearest (ids 1, 2)
  test::addRect(s, 0, 0, 4, 8, 0.6f, 1);   // green (ids 3, 4)
  test::addRect(s, 0, 0, 8, 8, 0.25f, 0);  // red, opaque (ids 5, 6)
  test::addRect(s, 4, 0, 8, 8, 0.1f, 1);   // green behind red (ids 7, 8)
  return s;
}

TEST(Visibility, TransparentPassSortedFarToNearOverOpaque) {
  const Frame f = renderReference(alphaScene(ColorFormat::RGBA32F));
  // red (1,0,0,1); green over it: (0.5, 0.5, 0, 0.5*0.5 + 1*0.5 = 0.75);
  // blue over that: (0.25, 0.25, 0.5, 0.25 + 0.375 = 0.625).
  const glm::dvec4 left = colorAt(f, 1, 3);
  EXPECT_EQ(left, glm::dvec4(0.25, 0.25, 0.5, 0.625));
  EXPECT_EQ(colorAt(f, 6, 3), glm::dvec4(1, 0, 0, 1));  // green behind red: depth test fails
  // Transparent fragments write ids but not depth.
  EXPECT_TRUE(f.id[f.index(1, 3)] == 1u || f.id[f.index(1, 3)] == 2u);
  EXPECT_TRUE(f.id[f.index(6, 3)] == 5u || f.id[f.index(6, 3)] == 6u);
  EXPECT_EQ(f.depth[f.index(1, 3)], static_cast<float>(12582911.0 / 16777215.0));  // red's 0.75
  // In file order (no sort) the result would differ: blue first, then green.
  const glm::dvec4 unsorted = glm::dvec4(0.5, 0.5 * 0.5 + 0.5 * 0.5 * 0.5, 0.25, 0.625);
  EXPECT_NE(left, unsorted);
}

TEST(Visibility, TransparentPassInRgba8RoundsEachStep) {
  const Frame f = renderReference(alphaScene(ColorFormat::RGBA8));
  // After green: 127.5 -> 128, 191.25 -> 191. After blue: r = g = 64, b = 127.5 -> 128,
  // a = 0.25 + 0.5 * 191 / 255 = 159.25 / 255 -> 159.
  EXPECT_EQ(colorAt(f, 1, 3),
            glm::dvec4(glm::vec4(64.0f / 255, 64.0f / 255, 128.0f / 255, 159.0f / 255)));
}

TEST(ColorFormat, Rgba8RoundsHalfToEvenAndClampsRgba32fDoesNot) {
  const double values[] = {0.2, 1.5 / 255, 2.5 / 255, 100.5 / 255, 101.5 / 255, 1.7, -0.3};
  const double rgba8[] = {51, 2, 2, 100, 102, 255, 0};
  for (ColorFormat fmt : {ColorFormat::RGBA8, ColorFormat::RGBA32F}) {
    Scene s = test::windowScene(8, 8);
    s.state.color_format = fmt;
    s.materials.clear();
    for (int i = 0; i < 7; ++i) {
      s.materials.push_back(flatColor(glm::dvec3(values[i])));
      test::addRect(s, static_cast<float>(i), 0, static_cast<float>(i + 1), 8, 0.5f, i);
    }
    s.clear_color = {0.5, 1.5, -1.0, 0.25};
    const Frame f = renderReference(s);
    for (int i = 0; i < 7; ++i) {
      const double expected = fmt == ColorFormat::RGBA8 ? rgba8[i] / 255.0 : values[i];
      EXPECT_EQ(f.color[4 * f.index(i, 4)], static_cast<float>(expected))
          << toString(fmt) << " value " << values[i];
      EXPECT_EQ(f.color[4 * f.index(i, 4) + 3], 1.0f);
    }
    // The clear colour is stored in the format too (GL converts clear values).
    const float* clear = &f.color[4 * f.index(7, 0)];
    if (fmt == ColorFormat::RGBA8) {
      EXPECT_EQ(clear[0], 128.0f / 255);
      EXPECT_EQ(clear[1], 1.0f);
      EXPECT_EQ(clear[2], 0.0f);
    } else {
      EXPECT_EQ(clear[1], 1.5f);
    }
  }
}

}  // namespace
}  // namespace rc
