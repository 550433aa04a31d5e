// GL vs the reference renderer on scenes covering every render state: wherever the
// reference is sure of the answer (edge_dist > 0.05 px and depth_gap > 4 steps) the two
// must see the same primitive, and depth and colour must agree within the tolerances
// measured on Mesa 22.3.6 (docs/gl_backend.md "Agreement with the reference").
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <numbers>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "fixtures/scene_logic.h"
#include "reference/reference_renderer.h"
#include "tests/gl/gl_test_util.h"

namespace rc::gltest {
namespace {

// UV sphere of radius 1 around the origin: normals = positions, u around, v up.
Mesh sphere(int segments, int rings) {
  Mesh m;
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::numbers::pi * r / rings;  // 0 at the north pole
    for (int s = 0; s <= segments; ++s) {
      const double phi = 2.0 * std::numbers::pi * s / segments;
      const glm::vec3 p(static_cast<float>(std::sin(theta) * std::cos(phi)),
                        static_cast<float>(std::cos(theta)),
                        static_cast<float>(-std::sin(theta) * std::sin(phi)));
      m.positions.push_back(p);
      m.normals.push_back(p);
      m.uvs.emplace_back(static_cast<float>(s) / segments, 1.0f - static_cast<float>(r) / rings);
    }
  }
  const auto at = [&](int r, int s) { return static_cast<std::uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      // Counter-clockwise seen from outside.
      if (r != 0) m.triangles.push_back({at(r, s), at(r + 1, s), at(r, s + 1)});
      if (r != rings - 1) m.triangles.push_back({at(r, s + 1), at(r + 1, s), at(r + 1, s + 1)});
    }
  }
  return m;
}

// An n x n grid in the xz plane at y = 0, [-1, 1]^2, normals +y, uvs [0, uv_scale]^2.
Mesh grid(int n, float uv_scale) {
  Mesh m;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
      m.positions.emplace_back(-1.0f + 2.0f * u, 0.0f, 1.0f - 2.0f * v);
      m.normals.emplace_back(0.0f, 1.0f, 0.0f);
      m.uvs.emplace_back(u * uv_scale, v * uv_scale);
    }
  }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return m;
}

glm::dmat4 trs(glm::dvec3 t, double angle_deg, glm::dvec3 axis, glm::dvec3 s) {
  glm::dmat4 m(1.0);
  m = glm::translate(m, t);
  m = glm::rotate(m, glm::radians(angle_deg), axis);
  return glm::scale(m, s);
}

std::shared_ptr<Texture> checker(int n) {
  auto t = std::make_shared<Texture>();
  t->width = n;
  t->height = n;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const bool odd = ((i / 2) + (j / 2)) % 2 != 0;
      t->rgba.insert(t->rgba.end(), {static_cast<std::uint8_t>(odd ? 230 : 40),
                                     static_cast<std::uint8_t>(40 + 12 * i),
                                     static_cast<std::uint8_t>(250 - 12 * j), 255});
    }
  }
  return t;
}

Material material(glm::dvec3 kd, double opacity = 1.0) {
  Material m;
  m.name = "m";
  m.ambient = kd * 0.3;
  m.diffuse = kd;
  m.specular = {0.6, 0.6, 0.6};
  m.shininess = 24.0;
  m.opacity = opacity;
  return m;
}

// Perspective camera at (0, 1.2, 4) looking at the origin, a sphere on a ground grid.
Scene baseScene(const std::string& name) {
  Scene s;
  s.name = "agreement/" + name;
  s.width = 160;
  s.height = 120;
  s.camera.eye = {0.3, 1.2, 4.0};
  s.camera.target = {0.0, 0.2, 0.0};
  s.camera.fovy_deg = 50.0;
  s.camera.near = 0.5;
  s.camera.far = 20.0;
  s.clear_color = {0.05, 0.05, 0.1, 1.0};
  s.ambient_light = {0.2, 0.2, 0.25};
  Light key;
  key.position = {2.0, 3.0, 2.5};
  key.intensity = 1.0;
  s.lights.push_back(key);
  Light fill;
  fill.type = LightType::Directional;
  fill.direction = {-1.0, -0.5, -0.3};
  fill.color = {0.4, 0.5, 0.7};
  fill.intensity = 0.6;
  s.lights.push_back(fill);
  s.materials.push_back(material({0.8, 0.3, 0.2}));
  s.materials.push_back(material({0.3, 0.7, 0.4}));
  Object ball;
  ball.name = "ball";
  ball.material = 0;
  ball.mesh = sphere(24, 12);
  ball.model = trs({0.0, 0.6, 0.0}, 20.0, {0, 1, 0}, {0.7, 0.7, 0.7});
  s.objects.push_back(ball);
  Object ground;
  ground.name = "ground";
  ground.material = 1;
  ground.mesh = grid(6, 3.0f);
  ground.model = trs({0.0, -0.1, 0.0}, 0.0, {0, 1, 0}, {3.0, 1.0, 3.0});
  s.objects.push_back(ground);
  return s;
}

struct AgreementCase {
  const char* name;
  std::function<void(Scene&)> edit;
};

// The case's name, not its bytes, in the test's listing (and so in its ctest name).
void PrintTo(const AgreementCase& c, std::ostream* os) { *os << c.name; }

const AgreementCase kCases[] = {
    {"phong_blinn", [](Scene&) {}},
    {"phong_phong_inverse",
     [](Scene& s) {
       s.state.specular_model = SpecularModel::Phong;
       s.state.attenuation = Attenuation::Inverse;
     }},
    {"gouraud_inverse_square",
     [](Scene& s) {
       s.state.shading = Shading::Gouraud;
       s.state.attenuation = Attenuation::InverseSquare;
     }},
    {"flat", [](Scene& s) { s.state.shading = Shading::Flat; }},
    {"textured_linear_repeat",
     [](Scene& s) {
       s.state.texture_filter = TextureFilter::Linear;
       for (Material& m : s.materials) m.texture = checker(16);
     }},
    {"textured_nearest_clamp",
     [](Scene& s) {
       s.state.texture_wrap = TextureWrap::Clamp;
       for (Material& m : s.materials) m.texture = checker(8);
     }},
    {"d16_rgba8",
     [](Scene& s) {
       s.state.depth_format = DepthFormat::D16;
       s.state.color_format = ColorFormat::RGBA8;
     }},
    {"d32f", [](Scene& s) { s.state.depth_format = DepthFormat::D32F; }},
    {"textured_gouraud",
     [](Scene& s) {
       s.state.shading = Shading::Gouraud;
       for (Material& m : s.materials) m.texture = checker(16);
     }},
    {"textured_flat_linear_clamp",
     [](Scene& s) {
       s.state.shading = Shading::Flat;
       s.state.texture_filter = TextureFilter::Linear;
       s.state.texture_wrap = TextureWrap::Clamp;
       for (Material& m : s.materials) m.texture = checker(8);
     }},
    {"cull_back_ccw",
     [](Scene& s) {
       s.state.cull = Cull::Back;  // default front face ccw: the sphere's outside, the ground
     }},
    {"cull_back_cw",
     [](Scene& s) {
       s.state.cull = Cull::Back;
       s.state.front_face = FrontFace::CW;  // shows the sphere's inside, hides the ground
     }},
    {"cull_front", [](Scene& s) { s.state.cull = Cull::Front; }},
    {"painter", [](Scene& s) { s.state.visibility = Visibility::Painter; }},
    {"no_depth_test", [](Scene& s) { s.state.depth_test = false; }},
    {"alpha_blend",
     [](Scene& s) {
       s.state.blend = Blend::Alpha;
       s.materials[0].opacity = 0.45;
     }},
    {"near_plane_crossing",
     [](Scene& s) {
       s.camera.eye = {0.0, 0.4, 1.0};
       s.camera.target = {0.0, 0.0, -2.0};
       s.camera.near = 0.3;
     }},
    {"orthographic",
     [](Scene& s) {
       s.camera.projection = Projection::Orthographic;
       s.camera.bounds = {-2.0, 2.0, -1.5, 1.5};
     }},
    {"nonuniform_scale",
     [](Scene& s) {
       s.objects[0].model = trs({0, 0.8, 0}, 35.0, {1, 0, 1}, {0.5, 1.2, 0.8});
     }},
};

// Tolerances from what was measured on Mesa 22.3.6, llvmpipe and softpipe (the table in
// docs/gl_backend.md), with margin:
//  - colour (float): measured <= 8e-6 absolute; shader float vs reference double.
//  - colour, linear texture filtering: llvmpipe filters unorm8 textures with 8-bit
//    weights, measured 0.88/255.
//  - colour, rgba8: one 8-bit step where the two sides round a value near k + 0.5.
//  - depth: measured <= 3 steps plus, on steep triangles, <= 3.2e-5 px times the depth
//    slope (near-plane crossing ground: 26 d24 steps at 1.2e6 steps/px); softpipe also
//    truncates (one step) and snaps clipped vertices to 1/16 px. Allowed: 4 steps plus
//    two subpixel steps of the slope.
constexpr double kColorFloat = 1e-4;
constexpr double kColorLinearTexture = 2.0 / 255.0;
constexpr double kColorRgba8 = 1.0 / 255.0 + 1e-7;
constexpr double kDepthSteps = 4.0;
constexpr double kDepthSnapSteps = 2.0;  // in subpixel steps (2^-subpixel_bits px) of slope

class GlAgreement : public GlTest, public ::testing::WithParamInterface<AgreementCase> {};

TEST_P(GlAgreement, SurePixelsAgree) {
  Scene s = baseScene(GetParam().name);
  GetParam().edit(s);
  const Frame gl = render(s);
  ReferenceOptions opts;
  opts.subpixel_bits = gl.meta.at("subpixel_bits").get<int>();
  const Frame ref = renderReference(s, opts);
  ASSERT_TRUE(ref.hasUncertainty());
  ASSERT_EQ(ref.pixelCount(), gl.pixelCount());

  const int bits = depthBits(s.state.depth_format);
  const double steps = bits > 0 ? std::ldexp(1.0, bits) - 1.0 : std::ldexp(1.0, 24);
  const double snap = std::ldexp(1.0, -opts.subpixel_bits);  // px
  const bool textured = s.materials[0].texture != nullptr;
  const double ctol = s.state.color_format == ColorFormat::RGBA8 ? kColorRgba8
                      : textured && s.state.texture_filter == TextureFilter::Linear
                          ? kColorLinearTexture
                          : kColorFloat;
  std::vector<std::uint32_t> object_of(1, UINT32_MAX);  // by primitive id
  for (const PrimitiveRef& p : flattenPrimitives(s)) object_of.push_back(p.object);
  std::size_t sure = 0, sure_mismatch = 0, compared = 0, depth_over = 0, color_over = 0;
  double max_depth = 0.0, max_color = 0.0, max_slope = 0.0;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const std::size_t i = ref.index(x, y);
      if (!(ref.edge_dist[i] > 0.05f && ref.depth_gap[i] > 4.0f)) continue;
      ++sure;
      if (ref.id[i] != gl.id[i]) {
        ++sure_mismatch;
        ADD_FAILURE() << s.name << ": pixel (" << x << ", " << y << ") ref id " << ref.id[i]
                      << " gl id " << gl.id[i] << " edge_dist " << ref.edge_dist[i] << " depth_gap "
                      << ref.depth_gap[i];
        continue;
      }
      if (ref.id[i] == 0) continue;
      ++compared;
      // Depth slope in steps per pixel from the reference's neighbours on the same object
      // (its surface is continuous across triangle edges; silhouettes are not).
      double slope = 0.0;
      for (const auto& [dx, dy] :
           {std::pair{1, 0}, std::pair{0, 1}, std::pair{-1, 0}, std::pair{0, -1}}) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= s.width || ny >= s.height) continue;
        const std::size_t j = ref.index(nx, ny);
        if (ref.id[j] != 0 && object_of[ref.id[j]] == object_of[ref.id[i]])
          slope = std::max(slope, std::abs(double(ref.depth[j]) - ref.depth[i]) * steps);
      }
      const double dz = std::abs(double(gl.depth[i]) - ref.depth[i]) * steps;
      max_depth = std::max(max_depth, dz);
      max_slope = std::max(max_slope, slope);
      if (dz > kDepthSteps + kDepthSnapSteps * snap * slope) ++depth_over;
      double dc = 0.0;
      for (int c = 0; c < 4; ++c)
        dc = std::max(dc, std::abs(double(gl.color[i * 4 + c]) - ref.color[i * 4 + c]));
      max_color = std::max(max_color, dc);
      if (dc > ctol) ++color_over;
    }
  }
  std::cout << "[ agreement ] " << s.name << " " << specText() << ": sure " << sure << ", compared "
            << compared << ", max depth " << max_depth << " steps, max colour " << max_color << " ("
            << max_color * 255.0 << " /255), max slope " << max_slope << " steps/px\n";
  RecordProperty("max_depth_steps", std::to_string(max_depth));
  RecordProperty("max_color_abs", std::to_string(max_color));
  EXPECT_GT(sure, ref.pixelCount() / 4) << "the scene should be mostly unambiguous";
  EXPECT_GT(compared, 0u);
  EXPECT_EQ(sure_mismatch, 0u);
  EXPECT_EQ(depth_over, 0u) << "max " << max_depth << " steps";
  EXPECT_EQ(color_over, 0u) << "max " << max_color;
}

INSTANTIATE_TEST_SUITE_P(Scenes, GlAgreement, ::testing::ValuesIn(kCases),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace rc::gltest
