// Scenes built in code: see test_scenes.h.
#include "tests/reference/test_scenes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>

#include "fixtures/generators.h"

namespace rc::test {

Scene windowScene(int width, int height) {
  Scene s;
  s.name = "test";
  s.width = width;
  s.height = height;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 1.0};
  s.camera.target = {0.0, 0.0, 0.0};
  s.camera.up = {0.0, 1.0, 0.0};
  s.camera.bounds = {0.0, static_cast<double>(width), 0.0, static_cast<double>(height)};
  s.camera.near = 0.0;
  s.camera.far = 1.0;
  s.ambient_light = glm::dvec3(1.0);
  Material white;
  white.name = "white";
  white.ambient = glm::dvec3(1.0);
  white.diffuse = glm::dvec3(0.0);
  white.specular = glm::dvec3(0.0);
  s.materials.push_back(white);
  return s;
}

std::size_t addMesh(Scene& scene, const std::vector<glm::vec3>& positions,
                    const std::vector<std::array<std::uint32_t, 3>>& triangles,
                    std::size_t material, const glm::vec3& normal,
                    const std::vector<glm::vec2>& uvs) {
  Object o;
  o.name = "object" + std::to_string(scene.objects.size());
  o.material = material;
  o.mesh.positions = positions;
  o.mesh.normals.assign(positions.size(), normal);
  o.mesh.uvs = uvs;
  o.mesh.triangles = triangles;
  scene.objects.push_back(std::move(o));
  return scene.objects.size() - 1;
}

std::size_t addTriangle(Scene& scene, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                        std::size_t material) {
  return addMesh(scene, {a, b, c}, {{0, 1, 2}}, material);
}

std::size_t addRect(Scene& scene, float x0, float y0, float x1, float y1, float z,
                    std::size_t material) {
  return addMesh(scene, {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}},
                 {{0, 1, 2}, {0, 2, 3}}, material, {0.0f, 0.0f, 1.0f},
                 {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}});
}

std::size_t addMaterial(Scene& scene, const Material& material) {
  scene.materials.push_back(material);
  return scene.materials.size() - 1;
}

Mesh sphereMesh(int segments, int rings) {
  Mesh m;
  const double pi = std::acos(-1.0);
  for (int r = 0; r <= rings; ++r) {
    const double theta = pi * r / rings;  // from +y down to -y
    for (int s = 0; s <= segments; ++s) {
      const double phi = 2.0 * pi * s / segments;
      const glm::vec3 p(static_cast<float>(std::sin(theta) * std::sin(phi)),
                        static_cast<float>(std::cos(theta)),
                        static_cast<float>(std::sin(theta) * std::cos(phi)));
      m.positions.push_back(p);
      m.normals.push_back(p);
      m.uvs.emplace_back(static_cast<float>(s) / segments, 1.0f - static_cast<float>(r) / rings);
    }
  }
  const auto row = static_cast<std::uint32_t>(segments + 1);
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t a = r * row + s;
      const std::uint32_t b = a + row;
      m.triangles.push_back({a, b, b + 1});  // counter-clockwise seen from outside
      m.triangles.push_back({a, b + 1, a + 1});
    }
  }
  return m;
}

namespace {

std::shared_ptr<const Texture> checkerTexture() {
  auto t = std::make_shared<Texture>();
  t->width = 4;
  t->height = 4;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const bool odd = ((i + j) & 1) != 0;
      t->rgba.insert(t->rgba.end(),
                     {static_cast<std::uint8_t>(odd ? 230 : 20), static_cast<std::uint8_t>(60 * i),
                      static_cast<std::uint8_t>(60 * j), 255});
    }
  return t;
}

// A lit perspective scene: a textured sphere, a ground plane crossing the near plane,
// a tilted transparent quad.
Scene litScene(Shading shading) {
  Scene s;
  s.name = "lit";
  s.width = 96;
  s.height = 64;
  s.camera.eye = {0.3, 1.2, 4.0};
  s.camera.target = {0.0, 0.0, 0.0};
  s.camera.fovy_deg = 50.0;
  s.camera.near = 0.5;
  s.camera.far = 30.0;
  s.ambient_light = {0.1, 0.1, 0.12};
  s.lights.push_back(
      Light{LightType::Point, {2.0, 3.0, 4.0}, {0.0, -1.0, 0.0}, {1.0, 0.9, 0.8}, 1.5});
  s.lights.push_back(
      Light{LightType::Directional, {0.0, 0.0, 0.0}, {-0.3, -1.0, -0.2}, {0.4, 0.5, 0.6}, 0.7});
  s.state.shading = shading;
  s.state.attenuation = Attenuation::Inverse;
  Material ball;
  ball.ambient = {0.3, 0.2, 0.2};
  ball.diffuse = {0.8, 0.5, 0.4};
  ball.specular = {1.0, 1.0, 1.0};
  ball.shininess = 24.0;
  ball.texture = checkerTexture();
  Material ground;
  ground.ambient = {0.2, 0.3, 0.2};
  ground.diffuse = {0.4, 0.7, 0.4};
  ground.specular = {0.2, 0.2, 0.2};
  ground.shininess = 7.5;
  Material glass;
  glass.ambient = {0.1, 0.1, 0.3};
  glass.diffuse = {0.2, 0.3, 0.9};
  glass.specular = {0.5, 0.5, 0.5};
  glass.opacity = 0.4;
  s.materials = {ball, ground, glass};
  Object sphere;
  sphere.name = "sphere";
  sphere.material = 0;
  sphere.mesh = sphereMesh(24, 12);
  sphere.model = glm::dmat4(glm::dvec4(1.0, 0.0, 0.0, 0.0), glm::dvec4(0.0, 1.5, 0.0, 0.0),
                            glm::dvec4(0.0, 0.0, 1.0, 0.0), glm::dvec4(0.0, 0.5, 0.0, 1.0));
  s.objects.push_back(sphere);
  Object plane;
  plane.name = "ground";
  plane.material = 1;
  plane.mesh.positions = {{-50, -1, -50}, {50, -1, -50}, {50, -1, 50}, {-50, -1, 50}};
  plane.mesh.normals.assign(4, {0, 1, 0});
  plane.mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
  s.objects.push_back(plane);
  Object quad;
  quad.name = "glass";
  quad.material = 2;
  quad.mesh.positions = {{-1.5, -1, 1.2}, {1.5, -1, 0.8}, {1.5, 2, 0.2}, {-1.5, 2, 0.6}};
  quad.mesh.normals.assign(4, {0, 0.3f, 1});
  quad.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(quad);
  return s;
}

}  // namespace

std::vector<NamedScene> featureScenes() {
  std::vector<NamedScene> out;
  for (Shading sh : {Shading::Flat, Shading::Gouraud, Shading::Phong}) {
    Scene s = litScene(sh);
    s.state.blend = Blend::Alpha;
    out.push_back({std::string("lit_") + toString(sh), s});
  }
  {
    Scene s = litScene(Shading::Phong);
    s.state.specular_model = SpecularModel::Phong;
    s.state.attenuation = Attenuation::InverseSquare;
    s.state.texture_filter = TextureFilter::Linear;
    s.state.texture_wrap = TextureWrap::Clamp;
    s.state.color_format = ColorFormat::RGBA8;
    s.state.depth_format = DepthFormat::D16;
    s.state.cull = Cull::Back;
    out.push_back({"lit_phong_rgba8_d16_cull", s});
  }
  {
    Scene s = litScene(Shading::Gouraud);
    s.state.visibility = Visibility::Painter;
    s.state.depth_format = DepthFormat::D32F;
    s.state.front_face = FrontFace::CW;
    s.state.cull = Cull::Front;
    out.push_back({"lit_painter_d32f_cw", s});
  }
  {
    // Many small and sliver triangles in window space.
    Scene s = windowScene(64, 64);
    s.state.shading = Shading::Flat;
    std::uint32_t seed = 12345u;
    auto rnd = [&]() {
      seed = seed * 1664525u + 1013904223u;
      return static_cast<float>((seed >> 8) & 0xffff) / 1024.0f;  // [0, 64), 1/1024 grid
    };
    for (int i = 0; i < 300; ++i) {
      const glm::vec3 a(rnd(), rnd(), 0.5f);
      const glm::vec3 b(a.x + (rnd() - 32.0f) / 8.0f, a.y + (rnd() - 32.0f) / 8.0f, 0.25f);
      const glm::vec3 c(rnd(), rnd(), 0.75f);
      addTriangle(s, a, b, c);
    }
    out.push_back({"window_random", s});
  }
  return out;
}

namespace {
template <class T>
void append(std::string& out, const std::vector<T>& v) {
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}
}  // namespace

std::string frameBytes(const Frame& frame) {
  std::string out;
  append(out, frame.color);
  append(out, frame.depth);
  append(out, frame.id);
  append(out, frame.stencil);
  for (const std::vector<float>* c : frame.uncertainty()) append(out, *c);
  return out;
}

namespace {
// A flat-shaded size x size window scene named `name` (the small-triangle benchmarks).
Scene flatWindowScene(int size, const char* name) {
  Scene s = windowScene(size, size);
  s.name = name;
  s.state.shading = Shading::Flat;
  return s;
}
}  // namespace

Scene smallTrianglesScene(int size, int count) {
  Scene s = flatWindowScene(size, "bench/small_triangles");
  Object o;
  o.name = "triangles";
  std::uint32_t seed = 1;
  auto rnd = [&]() {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / static_cast<float>(1 << 24) *
               static_cast<float>(size - 4) +
           1.0f;
  };
  for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(count); ++i) {
    const float x = rnd();
    const float y = rnd();
    const float z = 0.25f + 0.5f * static_cast<float>(i % 97) / 97.0f;
    o.mesh.positions.insert(o.mesh.positions.end(), {{x, y, z}, {x + 2, y, z}, {x, y + 2, z}});
    o.mesh.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  o.mesh.normals.assign(o.mesh.positions.size(), {0.0f, 0.0f, 1.0f});
  s.objects.push_back(std::move(o));
  return s;
}

Scene smallTriangleMeshScene(int size, int count) {
  Scene s = flatWindowScene(size, "bench/small_triangle_mesh");
  Object o;
  o.name = "grid";
  // cols x rows cells, as square as the window allows (2 px a cell).
  const int cells = std::max(1, count / 2);
  const int cols = std::max(1, std::min(size / 2 - 1, static_cast<int>(std::sqrt(cells))));
  const int rows = std::max(1, (cells + cols - 1) / cols);
  const float x0 = 0.5f * static_cast<float>(size - 2 * cols) + 0.25f;
  const float y0 = 0.5f * static_cast<float>(size - 2 * rows) + 0.25f;
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= cols; ++i) {
      const float z = 0.25f + 0.5f * static_cast<float>(i + j) / static_cast<float>(cols + rows);
      o.mesh.positions.emplace_back(x0 + 2.0f * static_cast<float>(i),
                                    y0 + 2.0f * static_cast<float>(j), z);
    }
  }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (cols + 1) + i); };
  for (int j = 0; j < rows && static_cast<int>(o.mesh.triangles.size()) < count; ++j) {
    for (int i = 0; i < cols && static_cast<int>(o.mesh.triangles.size()) < count; ++i) {
      o.mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      if (static_cast<int>(o.mesh.triangles.size()) < count)
        o.mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  o.mesh.normals.assign(o.mesh.positions.size(), {0.0f, 0.0f, 1.0f});
  s.objects.push_back(std::move(o));
  return s;
}

Scene layersScene(Shading shading, int size, int layers) {
  Scene s = windowScene(size, size);
  s.name = std::string("bench/layers_") + toString(shading);
  s.state.shading = shading;
  s.ambient_light = glm::dvec3(0.1);
  const double k = size / 1024.0;
  s.lights.push_back(
      Light{LightType::Point, {300.0 * k, 700.0 * k, 400.0 * k}, {}, {1.0, 1.0, 1.0}, 1.0});
  s.materials[0].diffuse = {0.6, 0.5, 0.4};
  s.materials[0].specular = glm::dvec3(0.5);
  s.materials[0].shininess = 32.0;
  const auto edge = static_cast<float>(size) + 1.0f;
  for (int layer = 0; layer < layers; ++layer)
    addRect(s, -1.0f, -1.0f, edge, edge, 0.1f + 0.1f * static_cast<float>(layer));
  return s;
}

Scene linesScene(int size, int count) {
  Scene s = windowScene(size, size);
  s.name = "bench/lines";
  s.state.shading = Shading::Gouraud;
  s.ambient_light = glm::dvec3(0.1);
  const double k = size / 1024.0;
  s.lights.push_back(
      Light{LightType::Point, {300.0 * k, 700.0 * k, 400.0 * k}, {}, {1.0, 1.0, 1.0}, 1.0});
  s.materials[0].diffuse = {0.6, 0.5, 0.4};
  std::uint32_t seed = 7;
  auto unit = [&]() {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / static_cast<float>(1 << 24);
  };
  const auto span = static_cast<float>(size - 64);
  Object thin;
  thin.name = "thin";
  thin.primitive = PrimitiveKind::Lines;
  Object wide = thin;
  wide.name = "wide";
  wide.state.line_width = 3.0;
  Object points;
  points.name = "points";
  points.primitive = PrimitiveKind::Points;
  points.state.point_size = 3.0;
  for (int i = 0; i < count; ++i) {
    const float x = 32.0f + unit() * span;
    const float y = 32.0f + unit() * span;
    const float z = 0.25f + 0.5f * unit();
    const float length = 2.0f + 58.0f * unit();
    const float angle = 6.2831853f * unit();
    Object& o = i % 3 == 0 ? wide : thin;
    const auto base = static_cast<std::uint32_t>(o.mesh.positions.size());
    o.mesh.positions.push_back({x, y, z});
    o.mesh.positions.push_back(
        {x + length * std::cos(angle), y + length * std::sin(angle), z + 0.1f * unit()});
    o.mesh.lines.push_back({base, base + 1});
    points.mesh.positions.push_back({32.0f + unit() * span, 32.0f + unit() * span, z});
  }
  for (Object* o : {&thin, &wide, &points}) {
    o->mesh.normals.assign(o->mesh.positions.size(), {0.0f, 0.0f, 1.0f});
    s.objects.push_back(std::move(*o));
  }
  return s;
}

Scene shadowScene(int size) {
  Scene s;
  s.name = "bench/shadow";
  s.width = size;
  s.height = size * 3 / 4;
  s.camera.eye = {0.0, 2.0, 3.6};
  s.camera.target = {0.0, 0.3, 0.0};
  s.camera.fovy_deg = 40.0;
  s.camera.near = 1.0;
  s.camera.far = 12.0;
  s.clear_color = {0.05, 0.05, 0.08, 1.0};
  s.ambient_light = glm::dvec3(0.15);
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = {-0.4, -1.0, -0.3};
  sun.shadow_map = "sun";
  s.lights.push_back(sun);
  s.targets.push_back(RenderTarget{"sun", size, size, TargetFormat::D24});
  Material pot;
  pot.name = "pot";
  pot.diffuse = {0.8, 0.5, 0.3};
  pot.specular = glm::dvec3(0.4);
  pot.shininess = 24.0;
  pot.shadow = ShadowLookup{"sun", TextureFilter::Nearest, CompareFunc::LEqual, 0.002, nullptr};
  Material floor;
  floor.name = "floor";
  floor.diffuse = glm::dvec3(0.7);
  floor.shadow = ShadowLookup{"sun", TextureFilter::Linear, CompareFunc::LEqual, 0.002, nullptr};
  s.materials = {pot, floor};
  const glm::dmat4 upright =
      glm::rotate(glm::dmat4(1.0), glm::radians(-90.0), glm::dvec3(1.0, 0.0, 0.0));
  Object teapot;
  teapot.name = "teapot";
  teapot.mesh = makeTeapot();
  teapot.model = upright * glm::scale(glm::dmat4(1.0), glm::dvec3(0.4));
  Object ground;
  ground.name = "floor";
  ground.material = 1;
  ground.mesh = makePlane();
  ground.model = upright * glm::scale(glm::dmat4(1.0), glm::dvec3(2.5, 2.5, 1.0));
  s.objects = {teapot, ground};
  s.state.shading = Shading::Phong;
  ScenePass map;
  map.target = "sun";
  Camera light;
  light.projection = Projection::Orthographic;
  light.eye = {1.6, 4.0, 1.2};
  light.bounds = {-2.2, 2.2, -2.2, 2.2};
  light.near = 0.5;
  light.far = 10.0;
  map.camera = light;
  map.state = s.state;
  map.state.cull = Cull::Front;
  ScenePass frame;
  frame.target = kFrameTarget;
  frame.clear_color = s.clear_color;
  frame.state = s.state;
  s.passes = {map, frame};
  return s;
}

}  // namespace rc::test
