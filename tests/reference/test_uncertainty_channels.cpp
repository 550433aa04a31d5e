// The reference's per-fragment uncertainty channels (frame.h UncertaintyChannel) against
// values worked out by hand from the scene geometry: depth_slope and gap_slope from the
// planes, texel_dist and texel_alt from texel boundaries and texel values, blend_count and
// blend_gap from the layers drawn.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "reference/fragment_ops.h"
#include "reference/reference_renderer.h"
#include "reference/shading.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr double kD24 = 16777215.0;

// windowScene maps world (x, y) to GL window (x, y) and world z to window depth 1 - z, so a
// plane z = a + b x + c y has |grad window z| = hypot(b, c) per px.
TEST(UncertaintyChannels, DepthSlopeIsTheGradientOfTheStoredFragmentsPlane) {
  Scene s = test::windowScene(16, 16);
  // z = 0.9 - 0.0125 (y + 16): a plane tilted in y over the whole window.
  test::addTriangle(s, {-16, -16, 0.9f}, {48, -16, 0.9f}, {-16, 48, 0.1f});
  const Frame f = renderReference(s);
  const float want = static_cast<float>(0.0125 * kD24);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      ASSERT_EQ(f.id[f.index(x, y)], 1u);
      EXPECT_NEAR(f.depth_slope[f.index(x, y)], want, want * 1e-6) << x << "," << y;
    }
  // Under d16 the same plane counts d16 steps.
  s.state.depth_format = DepthFormat::D16;
  const Frame d16 = renderReference(s);
  EXPECT_NEAR(d16.depth_slope[0], 0.0125 * 65535.0, 0.0125 * 65535.0 * 1e-6);
}

TEST(UncertaintyChannels, GapSlopeIsTheSteeperFragmentOfTheDecidingComparison) {
  Scene s = test::windowScene(16, 16);
  test::addRect(s, -1, -1, 17, 17, 0.5f);  // flat, window depth 0.5, drawn first
  // Steep, in front on the left: z = 0.9 - 0.05 x (window depth 0.1 + 0.05 x), behind for
  // x > 8.
  test::addTriangle(s, {-16, -16, 0.9f + 0.8f}, {48, -16, 0.9f - 2.4f}, {-16, 48, 0.9f + 0.8f});
  const Frame f = renderReference(s);
  const float steep = static_cast<float>(0.05 * kD24);
  for (int x : {2, 13}) {  // steep wins at x = 2, the flat one at x = 13
    const std::size_t i = f.index(x, 8);
    EXPECT_NEAR(f.gap_slope[i], steep, steep * 1e-6) << x;
    const double zs = 0.1 + 0.05 * (x + 0.5);
    EXPECT_NEAR(f.depth_gap[i], std::fabs(zs - 0.5) * kD24, 2.0) << x;
  }
  EXPECT_NEAR(f.depth_slope[f.index(2, 8)], steep, steep * 1e-6);
  EXPECT_EQ(f.depth_slope[f.index(13, 8)], 0.0f);  // the flat plane stored the depth there
}

// A 4x2 texture whose rows differ: row 0 (the bottom, v in [0, 0.5), stored first in
// Texture::rgba) bright (200, 220, 240), row 1 dark (10, 20, 40): 200 units apart at most.
std::shared_ptr<Texture> rowsTexture() {
  auto t = std::make_shared<Texture>();
  t->width = 4;
  t->height = 2;
  t->rgba.assign(std::size_t{4} * 8, 255);
  for (int i = 0; i < 4; ++i) {
    t->rgba[4 * i + 0] = 200;
    t->rgba[4 * i + 1] = 220;
    t->rgba[4 * i + 2] = 240;
    t->rgba[4 * (4 + i) + 0] = 10;
    t->rgba[4 * (4 + i) + 1] = 20;
    t->rgba[4 * (4 + i) + 2] = 40;
  }
  return t;
}
constexpr double kRowsContrast = 200.0;  // the largest channel difference of the two rows

TEST(UncertaintyChannels, ATriangleSampledExactlyOnATexelBoundaryMayTakeEitherTexel) {
  // uv (0, 1) at every vertex (as in assimp-testmodels spider.obj): v * 2 = 2 is a texel
  // boundary under repeat (row 2 wraps to row 0, the driver's 0.99999994 takes row 1).
  Scene s = test::windowScene(16, 16);
  s.materials[0].texture = rowsTexture();
  test::addMesh(s, {{0, 0, 0.5f}, {16, 0, 0.5f}, {0, 16, 0.5f}}, {{0, 1, 2}}, 0, {0, 0, 1},
                {{0, 1}, {0, 1}, {0, 1}});
  const Frame f = renderReference(s);
  const std::size_t i = f.index(3, 12);
  ASSERT_EQ(f.id[i], 1u);
  EXPECT_EQ(f.color[4 * i], 200.0f / 255.0f);  // the reference takes row 0 (bright)
  EXPECT_EQ(f.texel_dist[i], 0.0f);
  EXPECT_NEAR(f.texel_alt[i], kRowsContrast, 1e-3);  // the other row
  // Clamp-to-edge has no boundary at v = 1: nothing to choose.
  s.state.texture_wrap = TextureWrap::Clamp;
  const Frame c = renderReference(s);
  EXPECT_EQ(c.texel_dist[i], 1.0f);
  EXPECT_EQ(c.texel_alt[i], 0.0f);
  // Linear filtering has no texel boundary to cross; texel_alt is the colour range of the
  // footprint: at v = 1 (t = 2, repeat) it straddles rows 1 and 0 (2 - 0.5 = 1.5).
  s.state.texture_wrap = TextureWrap::Repeat;
  s.state.texture_filter = TextureFilter::Linear;
  const Frame l = renderReference(s);
  EXPECT_EQ(l.texel_dist[i], 1.0f);
  EXPECT_NEAR(l.texel_alt[i], kRowsContrast, 1e-3);
  EXPECT_EQ(l.texel_gain[i], 1.0f);  // ambient 1 x ambient light 1
  // At v = 0.1 (t - 0.5 = -0.3) under clamp both rows of the footprint are row 0: no
  // contrast. (A tap of weight 0 still counts: quantised weights may give it 2^-8.)
  s.state.texture_wrap = TextureWrap::Clamp;
  for (glm::vec2& uv : s.objects[0].mesh.uvs) uv = {0.375f, 0.1f};
  const Frame centre = renderReference(s);
  EXPECT_EQ(centre.texel_alt[i], 0.0f);
}

// texel_reach: how far float32 interpolation may move a linear-filtered sample (16 ulps of
// the magnitudes the coordinate comes from, docs/tolerances.md (c)). On an ordinary
// rectangle (0.25 texels per px) it is a small fraction of a texel and texel_alt stays the
// 2x2 footprint's range; on a sliver whose v runs to 50,000 across 0.6 px (~1.7e5 texels
// per px) it exceeds a texel, and texel_alt is the contrast of every footprint within it.
TEST(UncertaintyChannels, TexelReachFollowsTheTextureCoordinatesMagnitudes) {
  Scene s = test::windowScene(16, 16);
  s.materials[0].texture = rowsTexture();
  s.state.texture_filter = TextureFilter::Linear;
  test::addRect(s, 0, 0, 16, 16, 0.5f);
  const Frame f = renderReference(s);
  const std::size_t i = f.index(5, 10);  // s = 1.375, t = 0.6875: rows 0 and 1
  EXPECT_GT(f.texel_reach[i], 0.0f);
  EXPECT_LT(f.texel_reach[i], 1e-4f);
  EXPECT_NEAR(f.texel_alt[i], kRowsContrast, 1e-3);
  // Nearest filtering has its own reach (in texel_dist): texel_reach stays 0.
  s.state.texture_filter = TextureFilter::Nearest;
  EXPECT_EQ(renderReference(s).texel_reach[i], 0.0f);

  Scene sliver = test::windowScene(16, 16);
  sliver.materials[0].texture = rowsTexture();
  sliver.state.texture_filter = TextureFilter::Linear;
  test::addMesh(sliver, {{0, 8.0f, 0.5f}, {16, 8.5f, 0.5f}, {0, 8.6f, 0.5f}}, {{0, 1, 2}}, 0,
                {0, 0, 1}, {{0, 0}, {1, 0}, {0, 50000}});
  const Frame g = renderReference(sliver);
  int drawn = 0;
  for (std::size_t k = 0; k < g.pixelCount(); ++k) {
    if (g.id[k] == 0) continue;
    ++drawn;
    EXPECT_GT(g.texel_reach[k], 1.0f) << k;
    EXPECT_NEAR(g.texel_alt[k], kRowsContrast, 1e-3) << k;
  }
  EXPECT_GT(drawn, 3);
}

TEST(UncertaintyChannels, TexelDistIsTheScreenDistanceToTheNextTexelBoundary) {
  // A 4x2 texture over a 16x16 rectangle: a texel is 4 px wide and 8 px high, boundaries
  // at window x = 4, 8, 12 and y = 8 (and the wrap boundaries at 0 and 16).
  Scene s = test::windowScene(16, 16);
  s.materials[0].texture = rowsTexture();
  test::addRect(s, 0, 0, 16, 16, 0.5f);
  const Frame f = renderReference(s);
  // Pixel centre x = 3.5: 0.5 px from the boundary at x = 4 (in s, 0.125 texels at 0.25
  // texels/px); y = 5.5 (image row 10) is 2.5 px from y = 8 and 5.5 from 0: farther than 1.
  const std::size_t near_x = f.index(3, 10);
  EXPECT_NEAR(f.texel_dist[near_x], 0.5, 1e-4);
  EXPECT_EQ(f.texel_alt[near_x], 0.0f);  // the texels across x = 4 are the same colour
  // Pixel centre y = 7.5 (image row 8): 0.5 px below the row boundary at y = 8.
  const std::size_t near_y = f.index(5, 8);
  EXPECT_NEAR(f.texel_dist[near_y], 0.5, 1e-4);
  EXPECT_NEAR(f.texel_alt[near_y], kRowsContrast, 1e-3);
  // Pixel centre (5.5, 5.5): more than a pixel from every boundary.
  EXPECT_EQ(f.texel_dist[f.index(5, 10)], 1.0f);
  EXPECT_EQ(f.texel_alt[f.index(5, 10)], 0.0f);
  // An untextured opaque rectangle drawn over it clears what the texture left.
  test::addRect(s, 0, 0, 16, 16, 0.8f, test::addMaterial(s, s.materials[0]));
  s.materials.back().texture = nullptr;
  const Frame over = renderReference(s);
  EXPECT_EQ(over.texel_dist[near_y], 1.0f);
  EXPECT_EQ(over.texel_alt[near_y], 0.0f);
}

Material translucent(double opacity) {
  Material m;
  m.ambient = glm::dvec3(1.0);
  m.diffuse = glm::dvec3(0.0);
  m.specular = glm::dvec3(0.0);
  m.opacity = opacity;
  return m;
}

TEST(UncertaintyChannels, BlendCountAndBlendGapFollowTheTransparentLayers) {
  Scene s = test::windowScene(16, 16);
  s.state.blend = Blend::Alpha;
  test::addRect(s, -1, -1, 17, 17, 0.2f);  // opaque, window depth 0.8
  const std::size_t glass = test::addMaterial(s, translucent(0.5));
  test::addRect(s, -1, -1, 17, 8, 0.5f, glass);   // window depth 0.5, lower half (GL y < 8)
  test::addRect(s, -1, -1, 8, 17, 0.6f, glass);   // window depth 0.4, left half
  test::addRect(s, -1, -1, 17, 17, 0.3f, glass);  // window depth 0.7, everywhere
  const Frame f = renderReference(s);
  EXPECT_EQ(f.blend_count[f.index(3, 12)], 3.0f);   // left, GL y 3: all three
  EXPECT_EQ(f.blend_count[f.index(12, 12)], 2.0f);  // right, GL y 3
  EXPECT_EQ(f.blend_count[f.index(12, 3)], 1.0f);   // right, GL y 12: the full one
  // Every blended fragment is tested against the opaque depth 0.8; the closest is the full
  // layer at 0.7: 0.1 of the range.
  EXPECT_NEAR(f.blend_gap[f.index(3, 12)], 0.1 * kD24, 2.0);
  EXPECT_EQ(f.blend_slope[f.index(3, 12)], 0.0f);
  // Opaque only: nothing blended.
  s.state.blend = Blend::None;
  const Frame opaque = renderReference(s);
  for (float c : opaque.blend_count) EXPECT_EQ(c, 0.0f);
  for (float g : opaque.blend_gap) EXPECT_EQ(g, std::numeric_limits<float>::infinity());
}

// A z-fight under a transparent layer: which twin is under does not decide the id (the
// glass on top wins either way), but it decides the colour: blend_gap says so.
TEST(UncertaintyChannels, AZFightUnderAGlassLayerMakesTheBlendUncertain) {
  Scene s = test::windowScene(16, 16);
  s.state.blend = Blend::Alpha;
  Material dark = translucent(1.0);
  dark.ambient = glm::dvec3(0.1);
  test::addRect(s, -1, -1, 17, 17, 0.2f);                              // opaque, white
  test::addRect(s, -1, -1, 17, 17, 0.2f, test::addMaterial(s, dark));  // its dark twin
  test::addRect(s, -1, -1, 17, 17, 0.6f, test::addMaterial(s, translucent(0.5)));
  const Frame f = renderReference(s);
  const std::size_t i = f.index(5, 5);
  EXPECT_EQ(f.blend_count[i], 1.0f);
  EXPECT_EQ(f.blend_gap[i], 0.0f);                                   // the twins' depths are equal
  EXPECT_TRUE(std::isinf(f.depth_gap[i]) || f.depth_gap[i] > 1e6f);  // not the id's business
  // Without the twin, the only comparisons are the glass against the wall (window depths
  // 0.4 and 0.8) and the wall against the clear depth 1: the nearer, 0.2.
  s.objects.erase(s.objects.begin() + 1);
  const Frame single = renderReference(s);
  EXPECT_NEAR(single.blend_gap[i], 0.2 * kD24, 2.0);
}

TEST(UncertaintyChannels, TexelAltOfABlendedLayerIsWeightedByItsAlpha) {
  Scene s = test::windowScene(16, 16);
  s.state.blend = Blend::Alpha;
  test::addRect(s, -1, -1, 17, 17, 0.2f);  // opaque, untextured
  Material glass = translucent(0.25);
  glass.texture = rowsTexture();
  const std::size_t m = test::addMaterial(s, glass);
  test::addMesh(s, {{0, 0, 0.5f}, {16, 0, 0.5f}, {0, 16, 0.5f}}, {{0, 1, 2}}, m, {0, 0, 1},
                {{0, 1}, {0, 1}, {0, 1}});
  const Frame f = renderReference(s);
  const std::size_t i = f.index(3, 12);
  EXPECT_EQ(f.blend_count[i], 1.0f);
  EXPECT_EQ(f.texel_dist[i], 0.0f);
  EXPECT_NEAR(f.texel_alt[i], 0.25 * kRowsContrast, 1e-3);
}

// shade_reach (docs/tolerances.md (b)): in a Gouraud or Phong fan triangle thinner than a
// pixel, sum |b_k| times the largest channel's screen gradient of the colour, in 8-bit
// units per px, weighted by alpha when blended; 0 in thicker triangles (their neighbours
// show the gradient) and for flat shading. The expected value is computed here
// independently: the barycentrics from the pixel's trace, their gradient from the vertices
// (the window camera is affine), the colour as Gouraud or Phong defines it from
// shadePrepared(), differentiated by central differences.
// A 32 x 32 window scene in rgba32f, no ambient light, one point light of colour (1, 0.9,
// 0.8) at `light` with `intensity`, the material's diffuse, specular and shininess given.
Scene litWindowScene(Shading shading, const glm::dvec3& light, double intensity,
                     const glm::dvec3& diffuse, double specular, double shininess) {
  Scene s = test::windowScene(32, 32);
  s.state.shading = shading;
  s.state.color_format = ColorFormat::RGBA32F;
  s.ambient_light = glm::dvec3(0.0);
  s.lights.push_back(Light{LightType::Point, light, {}, {1.0, 0.9, 0.8}, intensity});
  s.materials[0].diffuse = diffuse;
  s.materials[0].specular = glm::dvec3(specular);
  s.materials[0].shininess = shininess;
  return s;
}

Scene litRamp(Shading shading) {
  Scene s = litWindowScene(shading, {16.0, 8.0, 50.0}, 2.0, {0.9, 0.7, 0.5}, 0.5, 8.0);
  const std::size_t o =
      test::addMesh(s, {{-8, -8, 0.5f}, {40, -8, 0.5f}, {-8, 40, 0.5f}}, {{0, 1, 2}});
  s.objects[o].mesh.normals = {{0.0f, 0.0f, 1.0f}, {0.6f, 0.0f, 0.8f}, {0.0f, 0.8f, 0.6f}};
  return s;
}

// The same triangle squeezed into a sliver about 0.002 px high whose bottom edge runs 0.001
// to 0.0015 px above the centres of window row 8: snapped to 1/256 px that edge moves onto
// them, so they are drawn though outside the exact triangle (sum |b_k| from 2 to about 2.5).
void makeSliver(Scene& s) {
  s.objects[0].mesh.positions = {{-8, 8.501f, 0.5f}, {40, 8.5015f, 0.5f}, {-8, 8.503f, 0.5f}};
}

// Checks every drawn pixel of `s` (one triangle, window scene) against the definition;
// returns the largest sum |b_k| seen.
double expectShadeReachIsTheGradient(const Scene& s, double weight, double tolerance) {
  const Frame g = renderReference(s);
  const ref::PreparedShading shading = ref::prepareShading(ref::sceneLighting(s), s.materials[0]);
  const Mesh& mesh = s.objects[0].mesh;
  glm::dvec3 lit_vertex[3];
  for (int k = 0; k < 3; ++k) {
    const ref::LitColor lit =
        ref::shadePrepared(shading, glm::dvec3(mesh.positions[k]), glm::dvec3(mesh.normals[k]));
    lit_vertex[k] = lit.ambient_diffuse + lit.specular;
  }
  auto colour = [&](const glm::dvec3& b) {
    if (s.state.shading == Shading::Gouraud)
      return b.x * lit_vertex[0] + b.y * lit_vertex[1] + b.z * lit_vertex[2];
    glm::dvec3 p(0.0);
    glm::dvec3 n(0.0);
    for (int k = 0; k < 3; ++k) {
      p += b[k] * glm::dvec3(mesh.positions[k]);
      n += b[k] * glm::dvec3(mesh.normals[k]);
    }
    const ref::LitColor lit = ref::shadePrepared(shading, p, ref::safeNormalize(n));
    return lit.ambient_diffuse + lit.specular;
  };
  const glm::dvec2 v0(mesh.positions[0]);
  const glm::dvec2 v1(mesh.positions[1]);
  const glm::dvec2 v2(mesh.positions[2]);
  const double area2 = (v1.x - v0.x) * (v2.y - v0.y) - (v2.x - v0.x) * (v1.y - v0.y);
  // grad b_k = perp(opposite edge) / area2, perp(e) = (-e.y, e.x) (counter-clockwise).
  const glm::dvec2 grad[3] = {glm::dvec2(-(v2.y - v1.y), v2.x - v1.x) / area2,
                              glm::dvec2(-(v0.y - v2.y), v0.x - v2.x) / area2,
                              glm::dvec2(-(v1.y - v0.y), v1.x - v0.x) / area2};
  int drawn = 0;
  double most = 0.0;
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      const std::size_t k = g.index(x, y);
      if (g.id[k] == 0) continue;
      ++drawn;
      const std::vector<FragmentTrace> trace = tracePixel(s, ReferenceOptions{}, x, y);
      EXPECT_EQ(trace.size(), 1u);
      if (trace.empty()) continue;
      const glm::dvec3 b = trace.back().barycentric;
      glm::dvec3 d[2];
      for (int a = 0; a < 2; ++a) {
        const glm::dvec3 db(grad[0][a], grad[1][a], grad[2][a]);
        const double h = 1e-5 / std::max({std::fabs(db.x), std::fabs(db.y), std::fabs(db.z)});
        d[a] = (colour(b + h * db) - colour(b - h * db)) / (2.0 * h);
      }
      double worst = 0.0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::hypot(d[0][c], d[1][c]));
      const double sum = std::fabs(b.x) + std::fabs(b.y) + std::fabs(b.z);
      most = std::max(most, sum);
      const double want = 255.0 * worst * sum * weight;
      EXPECT_GT(want, 1e4) << x << "," << y;
      EXPECT_NEAR(g.shade_reach[k], want, want * tolerance) << x << "," << y;
    }
  }
  EXPECT_GT(drawn, 3);
  return most;
}

// The thick ramp of `shading` records nothing (its neighbours show the gradient); its
// sliver matches the definition to `tolerance` where sum |b_k| reaches about 2. Returns
// the sliver.
Scene expectThickNothingSliverTheGradient(Shading shading, double tolerance) {
  const Scene thick = litRamp(shading);
  const Frame f = renderReference(thick);
  for (std::size_t k = 0; k < f.pixelCount(); ++k) {
    if (f.id[k] == 0) continue;
    EXPECT_EQ(f.shade_reach[k], 0.0f) << k;
  }
  Scene sliver = thick;
  makeSliver(sliver);
  EXPECT_GT(expectShadeReachIsTheGradient(sliver, 1.0, tolerance), 1.9);
  return sliver;
}

TEST(UncertaintyChannels, ShadeReachIsTheGouraudColoursGradient) {
  const Scene sliver = expectThickNothingSliverTheGradient(Shading::Gouraud, 1e-6);
  // Blended at opacity 0.25: a quarter of it.
  Scene blended = sliver;
  blended.materials[0].opacity = 0.25;
  blended.state.blend = Blend::Alpha;
  expectShadeReachIsTheGradient(blended, 0.25, 1e-6);
  // Flat: one colour per triangle, nothing to move.
  Scene flat = sliver;
  flat.state.shading = Shading::Flat;
  const Frame g = renderReference(flat);
  for (std::size_t k = 0; k < g.pixelCount(); ++k) EXPECT_EQ(g.shade_reach[k], 0.0f) << k;
}

// Phong's colour is not linear in the interpolated normal and position: the renderer's
// forward differences against these central ones, to 1e-3.
TEST(UncertaintyChannels, ShadeReachOfAPhongSliverIsItsColoursGradient) {
  expectThickNothingSliverTheGradient(Shading::Phong, 1e-3);
}

// normal_reach (docs/tolerances.md (a)): where a Phong triangle's interpolated normal can be
// short (vertex normals N0, 0, 0 here: n = b0 N0), a driver's float32 planes may turn it by
// 2 |e| / |n|, |e| = sqrt(3) 2^-20 (largest |N_k / w_k| / |1 / w| + |grad n| * image size),
// and the colour then moves by up to L (kd + s ks) per radian (Blinn, no attenuation),
// where n is under half as long as N0 (b0 < 1/2; 0 elsewhere). The
// window camera is affine (w = 1), so everything but b0 is constant: the channel is that
// formula, computed here from the vertices, at every drawn pixel whose normal is longer
// than |e|; with three equal normals nothing is recorded.
TEST(UncertaintyChannels, NormalReachFollowsTheShortNormal) {
  Scene s = litWindowScene(Shading::Phong, {16.0, 16.0, 40.0}, 1.5, {0.6, 0.5, 0.4}, 0.3, 16.0);
  const glm::vec3 v[3] = {{2, 2, 0.5f}, {30, 4, 0.5f}, {6, 29, 0.5f}};
  test::addMesh(s, {v[0], v[1], v[2]}, {{0, 1, 2}});
  const Frame same = renderReference(s);  // every normal (0, 0, 1)
  for (std::size_t k = 0; k < same.pixelCount(); ++k) EXPECT_EQ(same.normal_reach[k], 0.0f);

  s.objects[0].mesh.normals = {{0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  const Frame f = renderReference(s);
  const double area2 =
      (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
  // b0 = ((v1 - p) x (v2 - p)) / area2, grad b0 = perp(v2 - v1) / area2.
  const double grad_b0 = std::hypot(v[2].y - v[1].y, v[2].x - v[1].x) / std::fabs(area2);
  const double e = std::sqrt(3.0) * 0x1p-20 * (1.0 + grad_b0 * 32.0);
  const double k = 1.5 * (0.6 + 16.0 * 0.3);  // red: the largest channel
  int checked = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const std::size_t i = f.index(x, y);
      if (f.id[i] == 0) continue;
      const double px = x + 0.5;
      const double py = f.height - 1 - y + 0.5;  // GL window y
      const double b0 = ((v[1].x - px) * (v[2].y - py) - (v[2].x - px) * (v[1].y - py)) / area2;
      if (!(b0 > e)) continue;
      if (b0 >= 0.5) {  // at least half as long as N0: the relative term covers it
        EXPECT_EQ(f.normal_reach[i], 0.0f) << x << "," << y;
        continue;
      }
      const double want = 255.0 * 2.0 * e / b0 * k;
      EXPECT_NEAR(f.normal_reach[i], want, want * 1e-5) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

}  // namespace
}  // namespace rc
