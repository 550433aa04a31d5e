// Benchmark scenes: see bench_scenes.h. smallTriangles() and layers() are the reference
// benchmark's own scenes (rc_scene_builders), so the ratios compare the same work.
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

Scene smallTriangles() { return test::smallTrianglesScene(kRefSize, 100000); }

Scene smallTriangleMesh() { return test::smallTriangleMeshScene(kRefSize, 100000); }

Scene layers(Shading shading) { return test::layersScene(shading, kRefSize, 8); }

Scene linesAndPoints() { return test::linesScene(kRefSize, 20000); }

Scene shadowMap() { return test::shadowScene(kRefSize); }

}  // namespace rc::bench
