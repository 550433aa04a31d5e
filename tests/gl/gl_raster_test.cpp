// Visibility, depth, ids and fixed-function state on real GL against hand values:
// exact d16/d24/d32f depth of quads at known window z, LESS vs ALWAYS, painter's order,
// the alpha pass, culling with both windings, rgba8 rounding, textures at texel
// centres (nearest/linear, repeat/clamp), and a triangle crossing the near plane.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "tests/gl/gl_test_util.h"
#include "tests/support/printers.h"

namespace rc::gltest {
namespace {

class GlRaster : public GlTest {};

Material flatColor(const glm::dvec3& c, double opacity = 1.0) {
  Material m;
  m.name = "c";
  m.ambient = c;
  m.diffuse = glm::dvec3(0.0);
  m.opacity = opacity;
  return m;
}

// Ambient light 1: every pixel of an object is exactly its material's ambient colour.
Scene unlit(int w, int h) {
  Scene s = orthoScene(w, h);
  s.ambient_light = glm::dvec3(1.0);
  return s;
}

// The stored depth of a fragment at window z, as the driver under test quantizes it.
// GL lets fixed-point conversion pick either neighbour ("should round to nearest"):
// llvmpipe rounds to nearest (what DESIGN.md and the reference do); softpipe truncates
// a float product, (unsigned)(z * (float)(2^b - 1)) in sp_quad_depth_test.c. Clears
// round on both.
float storedDepth(DepthFormat f, double z, const std::string& driver = "llvmpipe") {
  if (f == DepthFormat::D32F) return static_cast<float>(z);
  const double steps = std::ldexp(1.0, depthBits(f)) - 1.0;
  if (driver == "softpipe") {
    const float product = static_cast<float>(z) * static_cast<float>(steps);
    return static_cast<float>(std::floor(product) / steps);
  }
  return static_cast<float>(std::nearbyint(z * steps) / steps);
}

std::string driverOf(const Frame& f) { return f.meta.at("driver").get<std::string>(); }

// Quad A (window z 0.75) on the left, quad B (window z 0.25) on the right, overlapping
// in the middle; A is first in the file.
Scene twoQuads(DepthFormat format) {
  Scene s = unlit(16, 8);
  s.state.depth_format = format;
  const std::size_t red = addMaterial(s, flatColor({1, 0, 0}));
  const std::size_t blue = addMaterial(s, flatColor({0, 0, 1}));
  s.objects.push_back(quad(-2.0, -2.0, 0.5, 2.0, -0.5, red));  // ids 1, 2
  s.objects.push_back(quad(-0.5, -2.0, 2.0, 2.0, 0.5, blue));  // ids 3, 4
  return s;
}

bool isA(std::uint32_t id) { return id == 1 || id == 2; }
bool isB(std::uint32_t id) { return id == 3 || id == 4; }

class GlDepthFormats : public GlTest, public ::testing::WithParamInterface<DepthFormat> {};

TEST_P(GlDepthFormats, NearerQuadWinsWithExactStoredDepth) {
  const DepthFormat format = GetParam();
  Scene s = twoQuads(format);
  const Frame f = render(s);
  const std::string driver = driverOf(f);
  const float za = storedDepth(format, 0.75, driver);
  const float zb = storedDepth(format, 0.25, driver);
  // Hand values, so a wrong rounding mode cannot hide behind the helper: 0.75 * 65535 =
  // 49151.25, 0.25 * 65535 = 16383.75, 0.75 * (2^24-1) = 12582911.25, 0.25 * (2^24-1) =
  // 4194303.75 (rounded: 4194304; softpipe truncates: 4194303).
  const bool trunc = driver == "softpipe";
  if (format == DepthFormat::D24) {
    EXPECT_EQ(za, static_cast<float>(12582911.0 / 16777215.0));
    EXPECT_EQ(zb, static_cast<float>((trunc ? 4194303.0 : 4194304.0) / 16777215.0));
  } else if (format == DepthFormat::D16) {
    EXPECT_EQ(za, static_cast<float>(49151.0 / 65535.0));
    EXPECT_EQ(zb, static_cast<float>((trunc ? 16383.0 : 16384.0) / 65535.0));
  }
  for (int y = 0; y < 8; ++y) {
    // Pixel centres x = -1 + (px+0.5)/8: px 0..3 only A, 4..11 both (B wins), 12..15 only B.
    for (int x = 0; x < 16; ++x) {
      const std::uint32_t id = f.id[f.index(x, y)];
      const float z = f.depth[f.index(x, y)];
      if (x < 4) {
        EXPECT_TRUE(isA(id)) << x << "," << y << " id " << id;
        EXPECT_EQ(z, za) << x << "," << y;
        EXPECT_EQ(colorAt(f, x, y), glm::dvec4(1, 0, 0, 1));
      } else {
        EXPECT_TRUE(isB(id)) << x << "," << y << " id " << id;
        EXPECT_EQ(z, zb) << x << "," << y;
        EXPECT_EQ(colorAt(f, x, y), glm::dvec4(0, 0, 1, 1));
      }
    }
  }
  // Which triangle: the quad's diagonal runs from its bottom-left to its top-right
  // corner; pixel (0, 7) (bottom-left) is below A's diagonal -> triangle 1, (0, 0) above -> 2.
  EXPECT_EQ(f.id[f.index(0, 7)], 1u);
  EXPECT_EQ(f.id[f.index(0, 0)], 2u);
  EXPECT_EQ(f.id[f.index(15, 7)], 3u);
  EXPECT_EQ(f.id[f.index(15, 0)], 4u);
}

TEST_P(GlDepthFormats, BackgroundKeepsClearDepthAndZeroId) {
  Scene s = unlit(8, 8);
  s.state.depth_format = GetParam();
  s.clear_depth = 0.75;
  s.clear_color = {0.25, 0.5, 0.75, 1.0};
  const Frame f = render(s);
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    ASSERT_EQ(f.id[i], 0u);
    ASSERT_EQ(f.depth[i], storedDepth(GetParam(), 0.75));
  }
  EXPECT_EQ(colorAt(f, 3, 3), glm::dvec4(0.25, 0.5, 0.75, 1.0));
}

TEST_P(GlDepthFormats, SlopedDepthReadsBackAsWholeSteps) {
  // A tilted plane covers many depth values: every stored value must be q / (2^b - 1)
  // for an integer q (d16/d24), i.e. the readback neither truncates nor blurs steps.
  const DepthFormat format = GetParam();
  Scene s = unlit(64, 64);
  s.state.depth_format = format;
  Object o = quad(-2, -2, 2, 2, 0, addMaterial(s, flatColor({1, 1, 1})));
  for (glm::vec3& p : o.mesh.positions) p.z = 0.37f * p.x + 0.11f * p.y;
  s.objects.push_back(o);
  const Frame f = render(s);
  std::set<float> distinct;
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    const float z = f.depth[i];
    distinct.insert(z);
    if (format != DepthFormat::D32F) {
      const double steps = std::ldexp(1.0, depthBits(format)) - 1.0;
      ASSERT_EQ(z, static_cast<float>(std::nearbyint(z * steps) / steps)) << i;
    }
    // The plane's window depth 0.5 - z/2 at this pixel centre. Drivers that clip the
    // quad to the viewport snap the new vertices to their subpixel grid, which tilts
    // the plane by up to about one subpixel step of its gradient (softpipe: ~1e-4 here).
    const int px = static_cast<int>(i % 64), py = static_cast<int>(i / 64);
    const glm::dvec2 w = pixelCentreWorld(s, px, py);
    const double want = 0.5 - (0.37 * w.x + 0.11 * w.y) / 2.0;
    const double gradient = (0.37 + 0.11) / 2.0 * (2.0 / 64.0);  // per pixel, |dz/dx|+|dz/dy|
    const double tol = 1e-6 + gradient * std::ldexp(1.0, -f.meta.at("subpixel_bits").get<int>());
    EXPECT_NEAR(z, want, tol) << px << "," << py;
  }
  EXPECT_GT(distinct.size(), 1000u);
}

INSTANTIATE_TEST_SUITE_P(Formats, GlDepthFormats,
                         ::testing::Values(DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F),
                         [](const auto& param_info) {
                           return std::string(toString(param_info.param));
                         });

TEST_F(GlRaster, DepthTestOffDrawsInFileOrder) {
  Scene s = twoQuads(DepthFormat::D24);
  s.state.depth_test = false;  // ALWAYS with writes: B (drawn last) wins, its depth stays
  Frame f = render(s);
  EXPECT_TRUE(isB(f.id[f.index(6, 4)]));
  // Swap the file order: now A is drawn last and wins although it is farther.
  std::swap(s.objects[0], s.objects[1]);
  f = render(s);
  EXPECT_TRUE(isB(f.id[f.index(6, 4)]));  // after the swap A owns ids 3, 4
  EXPECT_EQ(f.depth[f.index(6, 4)], storedDepth(DepthFormat::D24, 0.75, driverOf(f)));
  EXPECT_EQ(colorAt(f, 6, 4), glm::dvec4(1, 0, 0, 1));
}

TEST_F(GlRaster, PainterDrawsFarToNear) {
  Scene s = twoQuads(DepthFormat::D24);
  std::swap(s.objects[0], s.objects[1]);  // near quad (blue) first in the file: ids 1, 2
  s.state.visibility = Visibility::Painter;
  const Frame f = render(s);
  // Sorted far-to-near the near quad is drawn last and wins, with its own depth.
  EXPECT_EQ(colorAt(f, 6, 4), glm::dvec4(0, 0, 1, 1));
  EXPECT_TRUE(isA(f.id[f.index(6, 4)]));  // ids 1, 2 now belong to the near (blue) quad
  EXPECT_EQ(f.depth[f.index(6, 4)], storedDepth(DepthFormat::D24, 0.25, driverOf(f)));
  // Without painter and without depth test, file order puts the far quad on top.
  s.state.visibility = Visibility::ZBuffer;
  s.state.depth_test = false;
  const Frame g = render(s);
  EXPECT_EQ(colorAt(g, 6, 4), glm::dvec4(1, 0, 0, 1));
}

TEST_F(GlRaster, AlphaBlendOverOpaque) {
  Scene s = unlit(8, 8);
  s.state.blend = Blend::Alpha;
  const std::size_t red = addMaterial(s, flatColor({1, 0, 0}));
  const std::size_t glass = addMaterial(s, flatColor({0, 0, 1}, 0.25));
  s.objects.push_back(quad(-2, -2, 2, 2, 0.5, glass));  // in front, first in the file: 1, 2
  s.objects.push_back(quad(-2, -2, 2, 2, -0.5, red));   // behind: 3, 4
  const Frame f = render(s);
  // dst = src*a + dst*(1-a) on all four channels: rgb (0.75, 0, 0.25), a 0.25^2 + 0.75.
  EXPECT_EQ(colorAt(f, 2, 5), glm::dvec4(0.75, 0.0, 0.25, 0.8125));
  EXPECT_TRUE(isA(f.id[f.index(2, 5)]));  // the blended fragment writes its id
  // Depth writes are off in the transparent pass: the opaque depth stays.
  EXPECT_EQ(f.depth[f.index(2, 5)], storedDepth(DepthFormat::D24, 0.75, driverOf(f)));

  // Behind the opaque quad the transparent one fails the depth test.
  s.objects[0] = quad(-2, -2, 2, 2, -0.8, glass);
  const Frame g = render(s);
  EXPECT_EQ(colorAt(g, 2, 5), glm::dvec4(1, 0, 0, 1));
  EXPECT_TRUE(isB(g.id[g.index(2, 5)]));
}

TEST_F(GlRaster, TransparentTrianglesAreSortedFarToNear) {
  Scene s = unlit(8, 8);
  s.state.blend = Blend::Alpha;
  const std::size_t blue = addMaterial(s, flatColor({0, 0, 1}, 0.5));
  const std::size_t green = addMaterial(s, flatColor({0, 1, 0}, 0.5));
  s.objects.push_back(quad(-2, -2, 2, 2, 0.5, blue));    // near, first in the file
  s.objects.push_back(quad(-2, -2, 2, 2, -0.5, green));  // far
  const Frame f = render(s);
  // Far green over the clear (0,0,0,0): (0, .5, 0, .25); then near blue: (0, .25, .5, .375).
  // File order would have given (0, .5, .25, .375).
  EXPECT_EQ(colorAt(f, 4, 4), glm::dvec4(0.0, 0.25, 0.5, 0.375));
  EXPECT_TRUE(isA(f.id[f.index(4, 4)]));
}

TEST_F(GlRaster, CullingFollowsWindingAndFrontFace) {
  struct Case {
    Cull cull;
    FrontFace front;
    bool visible;
  };
  // The quad is counter-clockwise as seen by the camera.
  const Case cases[] = {{Cull::None, FrontFace::CCW, true},   {Cull::Back, FrontFace::CCW, true},
                        {Cull::Front, FrontFace::CCW, false}, {Cull::Back, FrontFace::CW, false},
                        {Cull::Front, FrontFace::CW, true},   {Cull::None, FrontFace::CW, true}};
  for (const Case& c : cases) {
    Scene s = unlit(8, 8);
    s.state.cull = c.cull;
    s.state.front_face = c.front;
    s.objects.push_back(quad(-2, -2, 2, 2, 0, addMaterial(s, flatColor({1, 1, 1}))));
    const Frame f = render(s);
    std::size_t covered = 0;
    for (std::uint32_t id : f.id) covered += id != 0 ? 1 : 0;
    EXPECT_EQ(covered, c.visible ? f.pixelCount() : 0u)
        << "cull " << toString(c.cull) << " front " << toString(c.front);
  }
  // A clockwise quad (mirrored winding) flips every answer.
  Scene s = unlit(8, 8);
  s.state.cull = Cull::Back;
  Object o = quad(-2, -2, 2, 2, 0, addMaterial(s, flatColor({1, 1, 1})));
  for (auto& t : o.mesh.triangles) std::swap(t[1], t[2]);
  s.objects.push_back(o);
  const Frame f = render(s);
  for (std::uint32_t id : f.id) ASSERT_EQ(id, 0u);
}

TEST_F(GlRaster, Rgba8ClampsAndRoundsToNearest) {
  Scene s = unlit(4, 4);
  s.state.color_format = ColorFormat::RGBA8;
  // 0.25*255 = 63.75 -> 64; 1.5 -> 255; -0.5 -> 0; alpha 0.6*255 = 153.
  s.objects.push_back(quad(-2, -2, 2, 2, 0, addMaterial(s, flatColor({0.25, 1.5, -0.5}, 0.6))));
  const Frame f = render(s);
  const glm::dvec4 want(static_cast<float>(64 / 255.0), 1.0, 0.0, static_cast<float>(153 / 255.0));
  EXPECT_EQ(colorAt(f, 1, 2), want);
}

// Texture tests: an 8x8 image, a 4x4 texture, uvs chosen so that even pixel columns sit
// on texel centres and odd ones exactly half-way between two texels (see
// docs/gl_backend.md). Texel values are even so that llvmpipe's 8-bit filter weights
// give exact midpoints.
std::shared_ptr<Texture> testTexture() {
  auto t = std::make_shared<Texture>();
  t->width = 4;
  t->height = 4;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      t->rgba.insert(t->rgba.end(), {static_cast<std::uint8_t>(10 + 60 * i),
                                     static_cast<std::uint8_t>(20 + 70 * j),
                                     static_cast<std::uint8_t>(200 - 40 * i), 255});
    }
  }
  return t;
}

Scene textureScene(TextureFilter filter, TextureWrap wrap) {
  Scene s = unlit(8, 8);
  s.state.texture_filter = filter;
  s.state.texture_wrap = wrap;
  Material m = flatColor({1, 1, 1});
  m.texture = testTexture();
  // u = s + 1/16 with s the screen fraction; the quad spans world [-2, 2] (s in [-0.5, 1.5]).
  s.objects.push_back(
      quad(-2, -2, 2, 2, 0, addMaterial(s, m), {-7 / 16.0f, -7 / 16.0f}, {25 / 16.0f, 25 / 16.0f}));
  return s;
}

// Texel (i, j) as the backend must return it: value / 255.
glm::dvec3 texel(int i, int j) {
  return glm::dvec3(10 + 60 * i, 20 + 70 * j, 200 - 40 * i) / 255.0;
}

void expectNear(const glm::dvec3& want, const glm::dvec4& got, int x, int y) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(want[c], got[c], 1e-6) << "pixel " << x << "," << y;
}

TEST_F(GlRaster, NearestTexelCentres) {
  const Frame f = render(textureScene(TextureFilter::Nearest, TextureWrap::Repeat));
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      const int x = 2 * i, y = 7 - 2 * j;  // GL row 2j is image row 7 - 2j
      expectNear(texel(i, j), colorAt(f, x, y), x, y);
    }
  }
}

TEST_F(GlRaster, LinearTexelCentresAndMidpoints) {
  const Frame f = render(textureScene(TextureFilter::Linear, TextureWrap::Repeat));
  // On a texel centre (both directions) linear returns the texel itself.
  expectNear(texel(1, 2), colorAt(f, 2, 7 - 4), 2, 3);
  // Half-way in u between texels 1 and 2 (x = 3), on a centre in v.
  expectNear((texel(1, 2) + texel(2, 2)) / 2.0, colorAt(f, 3, 7 - 4), 3, 3);
  // Half-way in both.
  expectNear((texel(1, 1) + texel(2, 1) + texel(1, 2) + texel(2, 2)) / 4.0, colorAt(f, 3, 4), 3, 4);
}

TEST_F(GlRaster, RepeatAndClampAtTheTextureEdge) {
  // Column 7 has u = 1.0: half-way between texel 3 and the next one, which is texel 0
  // with repeat and texel 3 again with clamp-to-edge. Image row 5 is GL row 2: the
  // centre of texel row 1.
  const int x = 7, y = 5, j = 1;
  const Frame rep = render(textureScene(TextureFilter::Linear, TextureWrap::Repeat));
  expectNear((texel(3, j) + texel(0, j)) / 2.0, colorAt(rep, x, y), x, y);
  const Frame clamp = render(textureScene(TextureFilter::Linear, TextureWrap::Clamp));
  expectNear(texel(3, j), colorAt(clamp, x, y), x, y);
  // Column 6 is texel 3's centre under either wrap.
  expectNear(texel(3, j), colorAt(clamp, 6, y), 6, y);
}

TEST_F(GlRaster, TriangleCrossingTheNearPlane) {
  // A ground quad at y = -1 from z = +1 (behind the camera at the origin) to z = -10,
  // very wide: the near plane clips it. A pixel row is covered iff its ray hits the
  // ground within 10 units: y_ndc < -1 / (10 tan(fovy/2)).
  Scene s;
  s.name = "gltest/near";
  s.width = 32;
  s.height = 32;
  s.camera.eye = {0, 0, 0};
  s.camera.target = {0, 0, -1};
  s.camera.fovy_deg = 90.0;
  s.camera.near = 0.1;
  s.camera.far = 100.0;
  s.ambient_light = glm::dvec3(1.0);
  Object o;
  o.material = addMaterial(s, flatColor({1, 1, 1}));
  o.mesh.positions = {{-1000, -1, 1}, {1000, -1, 1}, {1000, -1, -10}, {-1000, -1, -10}};
  o.mesh.normals.assign(4, glm::vec3(0, 1, 0));
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(o);
  const Frame f = render(s);
  const double tan_half = std::tan(glm::radians(45.0));
  for (int py = 0; py < 32; ++py) {
    const double y_ndc = 1.0 - 2.0 * (py + 0.5) / 32.0;
    const double limit = -1.0 / (10.0 * tan_half);       // -0.1
    if (std::abs(y_ndc - limit) < 2.0 / 32.0) continue;  // the far edge's row: either way
    const bool covered = y_ndc < limit;
    for (int px = 0; px < 32; ++px) {
      ASSERT_EQ(f.id[f.index(px, py)] != 0, covered) << px << "," << py;
    }
    if (covered) {
      // Depth of the ground point on this row: view z = -1 / (-y_ndc * tan_half).
      const double zv = -1.0 / (-y_ndc * tan_half);
      const double n = 0.1, fa = 100.0;
      const double z_ndc = (-(fa + n) / (fa - n) * zv - 2 * fa * n / (fa - n)) / -zv;
      EXPECT_NEAR(f.depth[f.index(16, py)], 0.5 * z_ndc + 0.5, 1e-5) << py;
    }
  }
  // The bottom row sees the ground just past the near plane: covered.
  EXPECT_NE(f.id[f.index(16, 31)], 0u);
}

}  // namespace
}  // namespace rc::gltest
