// Shading on real GL against hand-computed values: a full-screen quad under an
// orthographic camera, so every pixel centre has a known world position, and each
// term (ambient, diffuse, both specular models, attenuation, directional lights,
// pow(0,0), zero normals, Gouraud, flat, textures) is checked at known pixels.
#include <cmath>

#include <gtest/gtest.h>

#include "tests/gl/gl_test_util.h"

namespace rc::gltest {
namespace {

constexpr int kSize = 32;

// Relative float tolerance: the shader runs in float (and llvmpipe's pow/rsqrt are
// polynomial approximations), the oracle in double.
void expectColorNear(const glm::dvec3& want, const glm::dvec4& got, const char* what, int x,
                     int y) {
  for (int c = 0; c < 3; ++c) {
    const double tol = 2e-5 * std::max(1.0, std::abs(want[c]));
    EXPECT_NEAR(want[c], got[c], tol)
        << what << " channel " << c << " at pixel (" << x << ", " << y << ")";
  }
}

Material baseMaterial() {
  Material m;
  m.name = "m";
  m.ambient = {0.5, 0.25, 1.0};
  m.diffuse = {0.8, 0.6, 0.4};
  m.specular = {0.3, 0.5, 0.7};
  m.shininess = 16.0;
  m.opacity = 1.0;
  return m;
}

// A quad larger than the view at z = 0, facing the camera.
Scene shadingScene(const Material& m) {
  Scene s = orthoScene(kSize, kSize);
  s.ambient_light = {0.2, 0.3, 0.4};
  const std::size_t mi = addMaterial(s, m);
  s.objects.push_back(quad(-1.5, -1.5, 1.5, 1.5, 0.0, mi));
  return s;
}

glm::dvec3 worldAt(const Scene& s, int px, int py) {
  const glm::dvec2 xy = pixelCentreWorld(s, px, py);
  return {xy.x, xy.y, 0.0};
}

const int kPixels[][2] = {{0, 0}, {kSize - 1, 0}, {5, 20}, {16, 16}, {kSize - 1, kSize - 1}};

class GlShading : public GlTest {};

TEST_F(GlShading, AmbientOnlyIsMaterialTimesLight) {
  const Material m = baseMaterial();
  const Scene s = shadingScene(m);
  const Frame f = render(s);
  const glm::dvec3 want = m.ambient * s.ambient_light;
  for (const auto& p : kPixels) {
    expectColorNear(want, colorAt(f, p[0], p[1]), "ambient", p[0], p[1]);
    EXPECT_EQ(colorAt(f, p[0], p[1]).a, 1.0);
  }
}

TEST_F(GlShading, DirectionalDiffuseFollowsCosine) {
  Material m = baseMaterial();
  m.specular = glm::dvec3(0.0);
  Scene s = shadingScene(m);
  Light l;
  l.type = LightType::Directional;
  l.direction = {-1.0, 0.0, -1.0};  // travels to -x,-z: l = (1,0,1)/sqrt2, n.l = 1/sqrt2
  l.color = {1.0, 0.5, 0.25};
  l.intensity = 0.5;
  s.lights.push_back(l);
  const Frame f = render(s);
  const glm::dvec3 want = m.ambient * s.ambient_light + m.diffuse * l.color * 0.5 / std::sqrt(2.0);
  for (const auto& p : kPixels)
    expectColorNear(want, colorAt(f, p[0], p[1]), "diffuse", p[0], p[1]);
}

// Point light above the plane: n.l = h / r with h the light's height, attenuation 1,
// 1/r or 1/r^2 on top.
void checkPointAttenuation(Attenuation att) {
  Material m = baseMaterial();
  m.specular = glm::dvec3(0.0);
  Scene s = shadingScene(m);
  s.state.attenuation = att;
  Light l;
  l.position = {0.3, -0.2, 1.0};
  l.color = {0.9, 0.8, 0.7};
  l.intensity = 2.0;
  s.lights.push_back(l);
  const Frame f = GlTest::render(s);
  for (const auto& p : kPixels) {
    const glm::dvec3 pos = worldAt(s, p[0], p[1]);
    const double r = glm::length(l.position - pos);
    const double a = att == Attenuation::None      ? 1.0
                     : att == Attenuation::Inverse ? 1.0 / r
                                                   : 1.0 / (r * r);
    const glm::dvec3 want =
        m.ambient * s.ambient_light + m.diffuse * l.color * l.intensity * a * (1.0 / r);
    expectColorNear(want, colorAt(f, p[0], p[1]), toString(att), p[0], p[1]);
  }
}

TEST_F(GlShading, PointLightWithoutAttenuation) { checkPointAttenuation(Attenuation::None); }
TEST_F(GlShading, PointLightInverseAttenuation) { checkPointAttenuation(Attenuation::Inverse); }
TEST_F(GlShading, PointLightInverseSquareAttenuation) {
  checkPointAttenuation(Attenuation::InverseSquare);
}

// Specular at known pixels: eye (0,0,2), point light (0.5,0.5,1), n = +z.
void checkSpecular(SpecularModel model) {
  const Material m = baseMaterial();
  Scene s = shadingScene(m);
  s.state.specular_model = model;
  Light l;
  l.position = {0.5, 0.5, 1.0};
  l.color = {1.0, 1.0, 1.0};
  l.intensity = 1.0;
  s.lights.push_back(l);
  const Frame f = GlTest::render(s);
  const glm::dvec3 n(0, 0, 1);
  for (const auto& p : kPixels) {
    const glm::dvec3 pos = worldAt(s, p[0], p[1]);
    const glm::dvec3 lv = glm::normalize(l.position - pos);
    const glm::dvec3 v = glm::normalize(s.camera.eye - pos);
    double base = 0.0;
    if (model == SpecularModel::BlinnPhong) {
      base = std::max(0.0, glm::dot(n, glm::normalize(lv + v)));
    } else {
      const glm::dvec3 r = 2.0 * glm::dot(n, lv) * n - lv;
      base = std::max(0.0, glm::dot(r, v));
    }
    const glm::dvec3 want = m.ambient * s.ambient_light +
                            m.diffuse * std::max(0.0, glm::dot(n, lv)) +
                            m.specular * std::pow(base, m.shininess);
    expectColorNear(want, colorAt(f, p[0], p[1]), toString(model), p[0], p[1]);
  }
}

TEST_F(GlShading, BlinnPhongSpecular) { checkSpecular(SpecularModel::BlinnPhong); }
TEST_F(GlShading, PhongSpecular) { checkSpecular(SpecularModel::Phong); }

TEST_F(GlShading, BlinnAndPhongDiffer) {
  // Guards against both tests passing through one code path: at the corner pixel the
  // two models give clearly different highlights.
  Material m = baseMaterial();
  Scene s = shadingScene(m);
  Light l;
  l.position = {0.5, 0.5, 1.0};
  s.lights.push_back(l);
  s.state.specular_model = SpecularModel::BlinnPhong;
  const Frame blinn = render(s);
  s.state.specular_model = SpecularModel::Phong;
  const Frame phong = render(s);
  EXPECT_GT(std::abs(colorAt(blinn, 20, 8).b - colorAt(phong, 20, 8).b), 0.01);
}

TEST_F(GlShading, PowZeroZeroIsOne) {
  // Phong model, light from behind: r.v < 0, so the base is 0; with shininess 0 the
  // specular term is ks * L * 0^0 = ks * L, and no diffuse.
  Material m = baseMaterial();
  m.shininess = 0.0;
  Scene s = shadingScene(m);
  s.state.specular_model = SpecularModel::Phong;
  Light l;
  l.type = LightType::Directional;
  l.direction = {0.0, 0.0, 1.0};
  l.color = {0.5, 1.0, 0.25};
  s.lights.push_back(l);
  const Frame f = render(s);
  const glm::dvec3 want = m.ambient * s.ambient_light + m.specular * l.color;
  for (const auto& p : kPixels) expectColorNear(want, colorAt(f, p[0], p[1]), "0^0", p[0], p[1]);

  s.materials[0].shininess = 16.0;  // 0^16 = 0: ambient only
  const Frame g = render(s);
  const glm::dvec3 ambient = m.ambient * s.ambient_light;
  expectColorNear(ambient, colorAt(g, 3, 3), "0^16", 3, 3);
}

TEST_F(GlShading, ZeroNormalGivesAmbientOnly) {
  Material m = baseMaterial();
  m.shininess = 0.0;  // would make any specular term non-zero
  Scene s = shadingScene(m);
  s.objects[0].mesh.normals.assign(4, glm::vec3(0.0f));
  Light l;
  l.position = {0.0, 0.0, 1.0};
  s.lights.push_back(l);
  const Frame f = render(s);
  for (const auto& p : kPixels)
    expectColorNear(m.ambient * s.ambient_light, colorAt(f, p[0], p[1]), "zero normal", p[0], p[1]);
}

// The expected lit colour (ambient+diffuse, specular) at p with unit normal n, point
// light, Blinn-Phong, no attenuation.
void oracle(const Scene& s, const glm::dvec3& p, const glm::dvec3& n, glm::dvec3& ad,
            glm::dvec3& spec) {
  const Material& m = s.materials[0];
  const Light& l = s.lights[0];
  const glm::dvec3 lv = glm::normalize(l.position - p);
  const glm::dvec3 v = glm::normalize(s.camera.eye - p);
  const glm::dvec3 L = l.color * l.intensity;
  ad = m.ambient * s.ambient_light + m.diffuse * L * std::max(0.0, glm::dot(n, lv));
  spec = m.specular * L * std::pow(std::max(0.0, glm::dot(n, glm::normalize(lv + v))), m.shininess);
}

TEST_F(GlShading, GouraudInterpolatesVertexColours) {
  Material m = baseMaterial();
  m.shininess = 4.0;
  Scene s = shadingScene(m);
  s.state.shading = Shading::Gouraud;
  Light l;
  l.position = {0.2, 0.4, 0.8};
  s.lights.push_back(l);
  const Frame f = render(s);
  // Triangle (0,1,2) of the quad: (-1.5,-1.5), (1.5,-1.5), (1.5,1.5); the orthographic
  // camera makes screen-space and perspective-correct interpolation the same.
  const Object& o = s.objects[0];
  glm::dvec3 ad[3], sp[3];
  for (int k = 0; k < 3; ++k) oracle(s, glm::dvec3(o.mesh.positions[k]), {0, 0, 1}, ad[k], sp[k]);
  const int px = 24, py = 20;  // below the diagonal y = x: inside triangle (0,1,2)
  const glm::dvec3 p = worldAt(s, px, py);
  ASSERT_LT(p.y, p.x);
  const double b0 = (1.5 - p.x) / 3.0;
  const double b2 = (p.y + 1.5) / 3.0;
  const double b1 = 1.0 - b0 - b2;
  const glm::dvec3 want = b0 * (ad[0] + sp[0]) + b1 * (ad[1] + sp[1]) + b2 * (ad[2] + sp[2]);
  expectColorNear(want, colorAt(f, px, py), "gouraud", px, py);

  // And it is not per-pixel lighting.
  glm::dvec3 pad, psp;
  oracle(s, p, {0, 0, 1}, pad, psp);
  EXPECT_GT(glm::length(want - (pad + psp)), 0.01);
}

TEST_F(GlShading, FlatLightsTheCentroidWithTheFaceNormal) {
  Material m = baseMaterial();
  m.shininess = 4.0;
  Scene s = shadingScene(m);
  s.state.shading = Shading::Flat;
  s.objects[0].mesh.normals.assign(4, glm::vec3(1, 0, 0));  // ignored: the face normal is +z
  Light l;
  l.position = {0.2, 0.4, 0.8};
  s.lights.push_back(l);
  const Frame f = render(s);
  const Object& o = s.objects[0];
  const glm::dvec3 centroid = (glm::dvec3(o.mesh.positions[0]) + glm::dvec3(o.mesh.positions[1]) +
                               glm::dvec3(o.mesh.positions[2])) /
                              3.0;
  glm::dvec3 ad, sp;
  oracle(s, centroid, {0, 0, 1}, ad, sp);
  for (const auto& p : {std::array{24, 20}, std::array{30, 30}, std::array{31, 2}}) {
    const glm::dvec3 w = worldAt(s, p[0], p[1]);
    ASSERT_LT(w.y, w.x);  // all in triangle (0,1,2)
    expectColorNear(ad + sp, colorAt(f, p[0], p[1]), "flat", p[0], p[1]);
  }
}

TEST_F(GlShading, TextureMultipliesAmbientAndDiffuseNotSpecular) {
  Material m = baseMaterial();
  auto tex = std::make_shared<Texture>();
  tex->width = 1;
  tex->height = 1;
  tex->rgba = {102, 204, 51, 255};  // 0.4, 0.8, 0.2
  m.texture = tex;
  Scene s = shadingScene(m);
  Light l;
  l.position = {0.2, 0.4, 0.8};
  s.lights.push_back(l);
  const Frame f = render(s);
  const glm::dvec3 t(102 / 255.0, 204 / 255.0, 51 / 255.0);
  for (const auto& p : kPixels) {
    glm::dvec3 ad, sp;
    oracle(s, worldAt(s, p[0], p[1]), {0, 0, 1}, ad, sp);
    expectColorNear(t * ad + sp, colorAt(f, p[0], p[1]), "textured", p[0], p[1]);
  }
}

TEST_F(GlShading, ManyLightsAllContribute) {
  Material m = baseMaterial();
  m.specular = glm::dvec3(0.0);
  Scene s = shadingScene(m);
  for (int i = 0; i < 20; ++i) {  // more than the smallest light array (8)
    Light l;
    l.type = LightType::Directional;
    l.direction = {0.0, 0.0, -1.0};
    l.color = {1.0, 1.0, 1.0};
    l.intensity = 0.05;
    s.lights.push_back(l);
  }
  const Frame f = render(s);
  expectColorNear(m.ambient * s.ambient_light + m.diffuse, colorAt(f, 7, 9), "20 lights", 7, 9);
}

TEST_F(GlShading, OpacityIsAlpha) {
  Material m = baseMaterial();
  m.opacity = 0.375;
  const Frame f = render(shadingScene(m));
  EXPECT_EQ(colorAt(f, 4, 4).a, 0.375);
}

}  // namespace
}  // namespace rc::gltest
