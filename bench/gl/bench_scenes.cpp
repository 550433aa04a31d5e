// Benchmark scenes: see bench_scenes.h. smallTriangles() and layers() must stay equal to
// their twins in bench/reference/bench_reference.cpp (same seed, sizes and materials);
// move both into tests/reference/test_scenes.cpp once that library carries them.
#include "bench/gl/bench_scenes.h"

#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>

#include "tests/reference/test_scenes.h"

namespace rc::bench {

constexpr int kRefSize = 1024;

Scene sphere1080p(ColorFormat color) {
  Scene s;
  s.name = "bench/sphere_1080p";
  s.width = 1920;
  s.height = 1080;
  s.camera.eye = {0.0, 1.0, 4.0};
  s.camera.target = {0.0, 0.3, 0.0};
  s.ambient_light = {0.1, 0.1, 0.1};
  s.state.color_format = color;
  Light key;
  key.position = {2, 3, 3};
  s.lights.push_back(key);
  Light fill;
  fill.type = LightType::Directional;
  fill.direction = {-1, -1, -0.5};
  fill.intensity = 0.4;
  s.lights.push_back(fill);
  Material m;
  m.ambient = {0.8, 0.3, 0.2};
  m.diffuse = {0.8, 0.3, 0.2};
  m.specular = {0.5, 0.5, 0.5};
  s.materials.push_back(m);

  Object ball;
  ball.mesh = test::sphereMesh(64, 32);
  ball.model = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0.5, 0));
  s.objects.push_back(ball);

  Object ground;
  ground.mesh.positions = {{-5, -0.5f, 5}, {5, -0.5f, 5}, {5, -0.5f, -5}, {-5, -0.5f, -5}};
  ground.mesh.normals.assign(4, glm::vec3(0, 1, 0));
  ground.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(ground);
  return s;
}

Scene smallTriangles() {
  Scene s = test::windowScene(kRefSize, kRefSize);
  s.state.shading = Shading::Flat;
  Object o;
  std::uint32_t seed = 1;
  auto rnd = [&]() {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / static_cast<float>(1 << 24) * (kRefSize - 4) + 1.0f;
  };
  for (std::uint32_t i = 0; i < 100000; ++i) {
    const float x = rnd(), y = rnd(), z = 0.25f + 0.5f * (i % 97) / 97.0f;
    o.mesh.positions.insert(o.mesh.positions.end(), {{x, y, z}, {x + 2, y, z}, {x, y + 2, z}});
    o.mesh.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  o.mesh.normals.assign(o.mesh.positions.size(), {0.0f, 0.0f, 1.0f});
  s.objects.push_back(o);
  return s;
}

Scene layers(Shading shading) {
  Scene s = test::windowScene(kRefSize, kRefSize);
  s.state.shading = shading;
  s.ambient_light = glm::dvec3(0.1);
  s.lights.push_back(Light{LightType::Point, {300.0, 700.0, 400.0}, {}, {1.0, 1.0, 1.0}, 1.0});
  s.materials[0].diffuse = {0.6, 0.5, 0.4};
  s.materials[0].specular = glm::dvec3(0.5);
  s.materials[0].shininess = 32.0;
  for (int layer = 0; layer < 8; ++layer)
    test::addRect(s, -1.0f, -1.0f, kRefSize + 1.0f, kRefSize + 1.0f, 0.1f + 0.1f * layer);
  return s;
}

}  // namespace rc::bench
