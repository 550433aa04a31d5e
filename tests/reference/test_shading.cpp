// Shading and texturing against hand-computed values: every term at a known pixel, flat
// and Gouraud, the normal matrix on a non-uniformly scaled sphere, perspective-correct
// interpolation, texture lookups (nearest/linear, repeat/clamp).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "fixtures/scene_logic.h"
#include "reference/reference_renderer.h"
#include "reference/shading.h"
#include "reference/texture_sampling.h"
#include "reference/vertex_stage.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr double kTol = 1e-6;  // rgba32f stores floats

// 16 x 16, orthographic, camera at (0, 0, 10) looking down -z; bounds shifted half a pixel
// so that pixel (8, image row 7) has its centre at world (0, 0, 0), where v = (0, 0, 1).
// One triangle at z = 0 whose centroid is the origin, normals (0, 0, 1).
// Material: ka (0.2, 0.4, 0.6), kd 0.5, ks 1, shininess 8; ambient light 0.5.
Scene knownPixelScene(Shading shading) {
  Scene s;
  s.width = 16;
  s.height = 16;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 10.0};
  s.camera.bounds = {-8.5, 7.5, -8.5, 7.5};
  s.camera.near = 1.0;
  s.camera.far = 20.0;
  s.ambient_light = glm::dvec3(0.5);
  s.state.shading = shading;
  Material m;
  m.ambient = {0.2, 0.4, 0.6};
  m.diffuse = glm::dvec3(0.5);
  m.specular = glm::dvec3(1.0);
  m.shininess = 8.0;
  s.materials.push_back(m);
  test::addTriangle(s, {-20, -20, 0}, {40, -20, 0}, {-20, 40, 0});
  return s;
}

// Point light at (0, 3, 4): l = (0, 0.6, 0.8), r = 5, n.l = 0.8; L = (2, 1, 0.5).
Light pointLight() { return Light{LightType::Point, {0, 3, 4}, {0, -1, 0}, {1, 0.5, 0.25}, 2.0}; }

glm::dvec4 colorAt(const Frame& f, int x, int y) {
  const float* c = &f.color[4 * f.index(x, y)];
  return glm::dvec4(c[0], c[1], c[2], c[3]);
}

void expectColor(const glm::dvec4& actual, const glm::dvec4& expected, const char* what) {
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(actual[c], expected[c], kTol) << what << " channel " << c;
}

TEST(ShadingAtKnownPixel, EachTermAgainstHandComputedValues) {
  struct Case {
    const char* what;
    SpecularModel model;
    Attenuation att;
    double shininess;
    Light light;
    glm::dvec4 expected;
  };
  Light directional{LightType::Directional, {}, {0, -0.6, -0.8}, {1, 0.5, 0.25}, 2.0};
  Light behind{LightType::Point, {0, 0, -5}, {}, {1, 1, 1}, 1.0};
  const Case cases[] = {
      // ambient (0.1, 0.2, 0.3) + diffuse 0.5 * L * 0.8 = (0.8, 0.4, 0.2)
      // + Blinn-Phong: h = (0, 0.6, 1.8)/|.|, (n.h)^2 = 0.9, (n.h)^8 = 0.6561: L * 0.6561.
      {"blinn-phong",
       SpecularModel::BlinnPhong,
       Attenuation::None,
       8.0,
       pointLight(),
       {0.1 + 0.8 + 1.3122, 0.2 + 0.4 + 0.6561, 0.3 + 0.2 + 0.32805, 1.0}},
      // Phong: r = 2(n.l)n - l = (0, -0.6, 0.8), r.v = 0.8, ^2 = 0.64.
      {"phong",
       SpecularModel::Phong,
       Attenuation::None,
       2.0,
       pointLight(),
       {0.1 + 0.8 + 1.28, 0.2 + 0.4 + 0.64, 0.3 + 0.2 + 0.32, 1.0}},
      // 1/r: L = (0.4, 0.2, 0.1).
      {"inverse",
       SpecularModel::BlinnPhong,
       Attenuation::Inverse,
       8.0,
       pointLight(),
       {0.1 + 0.16 + 0.26244, 0.2 + 0.08 + 0.13122, 0.3 + 0.04 + 0.06561, 1.0}},
      // 1/r^2: L = (0.08, 0.04, 0.02).
      {"inverse_square",
       SpecularModel::BlinnPhong,
       Attenuation::InverseSquare,
       8.0,
       pointLight(),
       {0.1 + 0.032 + 0.052488, 0.2 + 0.016 + 0.026244, 0.3 + 0.008 + 0.013122, 1.0}},
      // Directional lights are never attenuated: same as the unattenuated point light.
      {"directional",
       SpecularModel::BlinnPhong,
       Attenuation::InverseSquare,
       8.0,
       directional,
       {0.1 + 0.8 + 1.3122, 0.2 + 0.4 + 0.6561, 0.3 + 0.2 + 0.32805, 1.0}},
      // Light behind the surface: n.l = -1, h = 0: ambient only.
      {"behind", SpecularModel::BlinnPhong, Attenuation::None, 8.0, behind, {0.1, 0.2, 0.3, 1.0}},
  };
  for (const Case& c : cases) {
    for (Shading sh : {Shading::Phong, Shading::Flat}) {
      Scene s = knownPixelScene(sh);
      s.state.specular_model = c.model;
      s.state.attenuation = c.att;
      s.materials[0].shininess = c.shininess;
      s.lights = {c.light};
      const Frame f = renderReference(s);
      expectColor(colorAt(f, 8, 7), c.expected, c.what);
      if (sh == Shading::Flat) expectColor(colorAt(f, 1, 14), c.expected, c.what);  // everywhere
    }
  }
  // Ambient only (no lights).
  expectColor(colorAt(renderReference(knownPixelScene(Shading::Phong)), 8, 7), {0.1, 0.2, 0.3, 1.0},
              "ambient");
}

TEST(ShadingAtKnownPixel, PhongVariesAcrossTheTriangleFlatDoesNot) {
  Scene s = knownPixelScene(Shading::Phong);
  s.lights = {pointLight()};
  const Frame phong = renderReference(s);
  EXPECT_GT(std::abs(colorAt(phong, 1, 14).r - colorAt(phong, 8, 7).r), 0.1);
}

TEST(ShadingAtKnownPixel, TraceReportsEveryTermAndTheyAddUp) {
  Scene s = knownPixelScene(Shading::Phong);
  s.lights = {pointLight(), Light{LightType::Directional, {}, {0, 0, -1}, {0.2, 0.2, 0.2}, 1.0}};
  const auto trace = tracePixel(s, {}, 8, 7);
  ASSERT_EQ(trace.size(), 1u);
  const ShadingTerms& t = trace[0].shading;
  ASSERT_EQ(t.lights.size(), 2u);
  EXPECT_NEAR(t.ambient.g, 0.2, 1e-12);
  EXPECT_NEAR(t.lights[0].diffuse.r, 0.8, 1e-12);
  EXPECT_NEAR(t.lights[0].specular.r, 1.3122, 1e-12);
  EXPECT_NEAR(t.lights[1].diffuse.r, 0.1, 1e-12);   // 0.5 * 0.2 * (n.l = 1)
  EXPECT_NEAR(t.lights[1].specular.r, 0.2, 1e-12);  // h = v = n: 0.2 * 1^8
  glm::dvec3 sum = t.ambient;
  glm::dvec3 spec(0.0);
  for (const LightTerms& l : t.lights) {
    sum += l.diffuse;
    spec += l.specular;
  }
  const glm::dvec3 rgb = sum * t.texture + spec;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(t.color[c], rgb[c], 1e-12);
  const Frame f = renderReference(s);
  expectColor(trace[0].color_written, colorAt(f, 8, 7), "trace vs frame");
}

// Three directional lights along +x, +y, +z coloured red, green, blue, and vertex normals
// (1,0,0), (0,1,0), (0,0,1): each vertex's Gouraud colour is one primary, so a
// fragment's rgb IS its perspective-correct barycentric coordinates.
Scene barycentricScene(Scene s, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  s.state.shading = Shading::Gouraud;
  s.ambient_light = glm::dvec3(0.0);
  s.lights = {Light{LightType::Directional, {}, {-1, 0, 0}, {1, 0, 0}, 1.0},
              Light{LightType::Directional, {}, {0, -1, 0}, {0, 1, 0}, 1.0},
              Light{LightType::Directional, {}, {0, 0, -1}, {0, 0, 1}, 1.0}};
  Material m;
  m.ambient = glm::dvec3(0.0);
  m.diffuse = glm::dvec3(1.0);
  m.specular = glm::dvec3(0.0);
  s.materials = {m};
  Object o;
  o.mesh.positions = {a, b, c};
  o.mesh.normals = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  o.mesh.triangles = {{0, 1, 2}};
  s.objects = {o};
  return s;
}

TEST(Gouraud, OrthographicColourIsTheScreenSpaceBarycentric) {
  const Scene s =
      barycentricScene(test::windowScene(16, 16), {1, 1, 0.5f}, {15, 1, 0.5f}, {1, 15, 0.5f});
  const Frame f = renderReference(s);
  // Pixel (4, GL row 6): centre (4.5, 6.5): b1 = 3.5 / 14, b2 = 5.5 / 14, b0 = 5 / 14.
  expectColor(colorAt(f, 4, 15 - 6), {5.0 / 14, 3.5 / 14, 5.5 / 14, 1.0}, "gouraud");
}

TEST(Interpolation, PerspectiveCorrectNotAffineOnATiltedTriangle) {
  Scene base;
  base.width = 64;
  base.height = 64;
  base.camera.eye = {0.0, 2.0, 3.0};
  base.camera.target = {0.0, 0.0, -4.0};
  base.camera.fovy_deg = 60.0;
  base.camera.near = 0.5;
  base.camera.far = 50.0;
  const glm::dvec3 A(-3, 0, 1), B(3, 0, 1), C(0, 0, -12);  // receding floor triangle
  const Scene s = barycentricScene(base, glm::vec3(A), glm::vec3(B), glm::vec3(C));
  const Frame f = renderReference(s);
  const glm::dmat4 vp = projectionMatrix(s.camera, 1.0) * viewMatrix(s.camera);
  const glm::dmat4 inv = glm::inverse(vp);
  auto screen = [&](const glm::dvec3& p) {
    const glm::dvec4 c = vp * glm::dvec4(p, 1.0);
    return glm::dvec2((c.x / c.w * 0.5 + 0.5) * 64, (c.y / c.w * 0.5 + 0.5) * 64);
  };
  const glm::dvec2 sa = screen(A), sb = screen(B), sc = screen(C);
  double max_affine_error = 0.0;
  int checked = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      if (f.id[f.index(x, y)] == 0 || f.edge_dist[f.index(x, y)] < 1.0f) continue;
      // Analytic: the ray through the pixel centre meets the plane y = 0 at P; its
      // barycentrics in the world triangle.
      const double nx = 2.0 * (x + 0.5) / 64 - 1.0, ny = 2.0 * ((63 - y) + 0.5) / 64 - 1.0;
      const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1, 1), b = inv * glm::dvec4(nx, ny, 1, 1);
      const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
      const glm::dvec3 P = p0 + (-p0.y / (p1.y - p0.y)) * (p1 - p0);
      const double area = glm::cross(B - A, C - A).y;
      const glm::dvec3 bary(glm::cross(B - P, C - P).y / area, glm::cross(C - P, A - P).y / area,
                            glm::cross(A - P, B - P).y / area);
      const glm::dvec4 got = colorAt(f, x, y);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], bary[c], 1e-5) << x << "," << y;
      // Affine (screen-space) barycentrics for comparison.
      const glm::dvec2 q(x + 0.5, 63 - y + 0.5);
      const double sarea = (sb.x - sa.x) * (sc.y - sa.y) - (sc.x - sa.x) * (sb.y - sa.y);
      const double l2 = ((sb.x - sa.x) * (q.y - sa.y) - (q.x - sa.x) * (sb.y - sa.y)) / sarea;
      max_affine_error = std::max(max_affine_error, std::abs(l2 - bary.z));
      ++checked;
    }
  EXPECT_GT(checked, 200);
  EXPECT_GT(max_affine_error, 0.05);  // affine interpolation would be visibly wrong
  // The trace reports the same barycentrics.
  const auto t = tracePixel(s, {}, 32, 50);
  ASSERT_EQ(t.size(), 1u);
  const glm::dvec4 got = colorAt(f, 32, 50);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(t[0].barycentric[c], got[c], 1e-6);
}

TEST(NormalMatrix, VertexStageUsesTheInverseTranspose) {
  Object o;
  o.mesh.positions = {{0, 0.5f, 0}};
  o.mesh.normals = {{0.0f, 0.5f, static_cast<float>(std::sqrt(0.75))}};
  o.model = glm::dmat4(1.0);
  o.model[1][1] = 3.0;  // scale (1, 3, 1)
  ref::CameraTransform cam;
  std::vector<ref::TransformedVertex> out;
  ref::transformObject(o, cam, out);
  // (0, 0.5, sqrt(.75)) * inverse-transpose diag(1, 1/3, 1) = (0, 1/6, sqrt(.75)), normalized.
  const double len = std::sqrt(1.0 / 36 + 0.75);
  EXPECT_NEAR(out[0].normal.y, (1.0 / 6) / len, 1e-7);
  EXPECT_NEAR(out[0].normal.z, std::sqrt(0.75) / len, 1e-7);
  EXPECT_NEAR(out[0].world.y, 1.5, 1e-12);
}

TEST(NormalMatrix, ScaledSphereNormalMatchesTheAnalyticEllipsoidNormal) {
  Scene s;
  s.width = 32;
  s.height = 64;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0, 0, 10};
  // 1/8 unit per pixel, shifted so that pixel (16, GL row 44) is centred on (0, 1.5).
  s.camera.bounds = {-2.0 - 1.0 / 16, 2.0 - 1.0 / 16, -4.0 - 1.0 / 16, 4.0 - 1.0 / 16};
  s.camera.near = 1;
  s.camera.far = 20;
  s.state.shading = Shading::Phong;
  s.lights = {Light{LightType::Directional, {}, {-1, 0, 0}, {1, 0, 0}, 1.0},
              Light{LightType::Directional, {}, {0, -1, 0}, {0, 1, 0}, 1.0},
              Light{LightType::Directional, {}, {0, 0, -1}, {0, 0, 1}, 1.0}};
  Material m;
  m.diffuse = glm::dvec3(1.0);
  m.specular = glm::dvec3(0.0);
  s.materials = {m};
  Object sphere;
  sphere.mesh = test::sphereMesh(96, 48);
  sphere.model = glm::dmat4(1.0);
  sphere.model[1][1] = 3.0;
  s.objects = {sphere};
  const Frame f = renderReference(s);
  // Ellipsoid x^2 + (y/3)^2 + z^2 = 1 at (0, 1.5, sqrt(.75)): normal ~ (0, y/9, z).
  const double len = std::sqrt(1.0 / 36 + 0.75);
  const glm::dvec4 c = colorAt(f, 16, 63 - 44);
  EXPECT_NEAR(c.r, 0.0, 0.01);
  EXPECT_NEAR(c.g, (1.0 / 6) / len, 0.01);  // 0.189
  EXPECT_NEAR(c.b, std::sqrt(0.75) / len, 0.01);
  // Transforming normals with the model matrix instead would give (0, 0.866, 0.5).
  EXPECT_GT(std::abs(c.g - 0.866), 0.5);
}

// ---- textures ------------------------------------------------------------------------------

// Texel (i, j) = (16 i + 64 j, 255 - 16 i, 64 j, 255) / 255.
std::shared_ptr<Texture> gradientTexture() {
  auto t = std::make_shared<Texture>();
  t->width = 4;
  t->height = 4;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      t->rgba.insert(t->rgba.end(), {static_cast<std::uint8_t>(16 * i + 64 * j),
                                     static_cast<std::uint8_t>(255 - 16 * i),
                                     static_cast<std::uint8_t>(64 * j), 255});
  return t;
}

glm::dvec4 texel(int i, int j) {
  return glm::dvec4(16 * i + 64 * j, 255 - 16 * i, 64 * j, 255) / 255.0;
}

TEST(TextureSampling, NearestAndLinearAtTexelCentresAndBetween) {
  const auto t = gradientTexture();
  using ref::sampleTexture;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const glm::dvec2 centre((i + 0.5) / 4, (j + 0.5) / 4);
      for (TextureWrap w : {TextureWrap::Repeat, TextureWrap::Clamp}) {
        EXPECT_EQ(sampleTexture(*t, centre, TextureFilter::Nearest, w), texel(i, j));
        const glm::dvec4 lin = sampleTexture(*t, centre, TextureFilter::Linear, w);
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(lin[c], texel(i, j)[c], 1e-15);
      }
    }
  // Halfway between texel centres (1, 1) and (2, 1): the mean.
  const glm::dvec4 mid =
      sampleTexture(*t, {0.5, 0.375}, TextureFilter::Linear, TextureWrap::Repeat);
  EXPECT_NEAR(mid.r, (texel(1, 1).r + texel(2, 1).r) / 2, 1e-15);
  // Wrapping: u = -0.1 -> texel 3 (repeat) or 0 (clamp); u = 1.3 -> 1 or 3.
  EXPECT_EQ(sampleTexture(*t, {-0.1, 0.1}, TextureFilter::Nearest, TextureWrap::Repeat),
            texel(3, 0));
  EXPECT_EQ(sampleTexture(*t, {-0.1, 0.1}, TextureFilter::Nearest, TextureWrap::Clamp),
            texel(0, 0));
  EXPECT_EQ(sampleTexture(*t, {1.3, 0.1}, TextureFilter::Nearest, TextureWrap::Repeat),
            texel(1, 0));
  EXPECT_EQ(sampleTexture(*t, {1.3, 0.1}, TextureFilter::Nearest, TextureWrap::Clamp), texel(3, 0));
  // Non-finite coordinates sample texel 0 instead of crashing.
  EXPECT_EQ(sampleTexture(*t, {std::nan(""), 0.1}, TextureFilter::Linear, TextureWrap::Repeat).g,
            texel(0, 0).g);
  EXPECT_EQ(sampleTexture(*t, {1e300, -1e300}, TextureFilter::Nearest, TextureWrap::Repeat).a, 1.0);
}

// An 8 x 8 window scene showing the texture on a full-viewport rectangle, uv (0,0)-(1,1):
// ambient 1 x ambient light 1, so colour = texel.
Frame texturedFrame(TextureFilter filter, TextureWrap wrap, float uv_lo = 0, float uv_hi = 1) {
  Scene s = test::windowScene(8, 8);
  s.materials[0].texture = gradientTexture();
  s.state.texture_filter = filter;
  s.state.texture_wrap = wrap;
  test::addMesh(s, {{0, 0, 0.5f}, {8, 0, 0.5f}, {8, 8, 0.5f}, {0, 8, 0.5f}}, {{0, 1, 2}, {0, 2, 3}},
                0, {0, 0, 1}, {{uv_lo, uv_lo}, {uv_hi, uv_lo}, {uv_hi, uv_hi}, {uv_lo, uv_hi}});
  return renderReference(s);
}

TEST(TextureSampling, ThroughTheRenderer) {
  // Pixel centre px + 0.5 -> u * 4 = (px + 0.5) / 2.
  const Frame nearest = texturedFrame(TextureFilter::Nearest, TextureWrap::Repeat);
  expectColor(colorAt(nearest, 3, 7 - 5), texel(1, 2), "nearest (3, 5)");
  expectColor(colorAt(nearest, 0, 7), texel(0, 0), "nearest (0, 0)");
  const Frame repeat = texturedFrame(TextureFilter::Linear, TextureWrap::Repeat);
  // (1, 1): s - 0.5 = 0.25 in both: affine texels -> value at (0.25, 0.25) = (20, 251, 16).
  expectColor(colorAt(repeat, 1, 6), glm::dvec4(20, 251, 16, 255) / 255.0, "linear (1, 1)");
  // (0, 0): taps (3|0) x (3|0) with weights 0.25 / 0.75: r = 60, g = 243, b = 48.
  expectColor(colorAt(repeat, 0, 7), glm::dvec4(60, 243, 48, 255) / 255.0, "linear repeat (0, 0)");
  const Frame clamp = texturedFrame(TextureFilter::Linear, TextureWrap::Clamp);
  expectColor(colorAt(clamp, 0, 7), texel(0, 0), "linear clamp (0, 0)");
  // uv -1 .. 2 across the image: px 5 -> u = 1.0625 -> s = 4.25: texel 0 (repeat), 3 (clamp).
  const Frame wide_r = texturedFrame(TextureFilter::Nearest, TextureWrap::Repeat, -1, 2);
  const Frame wide_c = texturedFrame(TextureFilter::Nearest, TextureWrap::Clamp, -1, 2);
  EXPECT_NEAR(colorAt(wide_r, 5, 7 - 5).r, texel(0, 0).r, kTol);
  EXPECT_NEAR(colorAt(wide_c, 5, 7 - 5).r, texel(3, 3).r, kTol);
}

TEST(TextureSampling, TextureMultipliesAmbientAndDiffuseNotSpecular) {
  Scene s = knownPixelScene(Shading::Phong);
  s.lights = {pointLight()};
  auto t = std::make_shared<Texture>();
  t->width = 1;
  t->height = 1;
  t->rgba = {51, 102, 255, 0};  // (0.2, 0.4, 1.0)
  s.materials[0].texture = t;
  const Frame f = renderReference(s);
  // (ambient + diffuse) * t + specular; the texture's alpha is not used.
  expectColor(colorAt(f, 8, 7), {0.9 * 0.2 + 1.3122, 0.6 * 0.4 + 0.6561, 0.5 * 1.0 + 0.32805, 1.0},
              "textured");
}

TEST(ShadingUnit, SpecularPowerAndZeroNormals) {
  using ref::specularPower;
  EXPECT_EQ(specularPower(0.0, 0.0), 1.0);  // pow(0, 0) := 1
  EXPECT_EQ(specularPower(-0.5, 0.0), 1.0);
  EXPECT_EQ(specularPower(-0.5, 8.0), 0.0);
  EXPECT_EQ(specularPower(0.0, 8.0), 0.0);
  for (double s : {1.0, 2.0, 7.0, 32.0, 127.0, 128.0, 1000.0, 2.5})
    EXPECT_NEAR(specularPower(0.97, s), std::pow(0.97, s), s * 0x1p-52 * std::pow(0.97, s)) << s;
  Scene s = knownPixelScene(Shading::Phong);
  s.lights = {pointLight()};
  const ref::Lighting lighting = ref::sceneLighting(s);
  ShadingTerms terms;
  const ref::LitColor lit =
      ref::shadePoint(lighting, s.materials[0], {0, 0, 0}, glm::dvec3(0.0), &terms);
  EXPECT_EQ(lit.ambient_diffuse, glm::dvec3(0.1, 0.2, 0.3));  // ambient only
  EXPECT_EQ(lit.specular, glm::dvec3(0.0));
  ASSERT_EQ(terms.lights.size(), 1u);
  EXPECT_EQ(terms.lights[0].diffuse, glm::dvec3(0.0));
  // A point light exactly at the shaded point contributes nothing (instead of NaN).
  s.lights[0].position = {0, 0, 0};
  s.state.attenuation = Attenuation::Inverse;
  const ref::LitColor at =
      ref::shadePoint(ref::sceneLighting(s), s.materials[0], {0, 0, 0}, {0, 0, 1});
  EXPECT_EQ(at.specular, glm::dvec3(0.0));
  EXPECT_EQ(at.ambient_diffuse, glm::dvec3(0.1, 0.2, 0.3));
}

}  // namespace
}  // namespace rc
