// Small scenes built in code for the debug library's tests: a camera looking down -z at a
// lit quad, so that the factors and terms at the centre pixel have closed forms.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fixtures/scene.h"

namespace rc::debugtest {

// A 3x3 orthographic image of [-1.5, 1.5]^2 seen from eye (0, 0, 5): pixel (1, 1)'s centre
// is the world origin. No objects, no lights, no ambient light; one material "m" with
// diffuse 1, specular 1, shininess 1, ambient 0.
inline Scene litWindow() {
  Scene s;
  s.name = "debug/lit_window";
  s.width = 3;
  s.height = 3;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 5.0};
  s.camera.target = {0.0, 0.0, 0.0};
  s.camera.up = {0.0, 1.0, 0.0};
  s.camera.bounds = {-1.5, 1.5, -1.5, 1.5};
  s.camera.near = 1.0;
  s.camera.far = 10.0;
  Material m;
  m.name = "m";
  m.ambient = glm::dvec3(0.0);
  m.diffuse = glm::dvec3(1.0);
  m.specular = glm::dvec3(1.0);
  m.shininess = 1.0;
  s.materials.push_back(m);
  return s;
}

// The rectangle [x0, x1] x [y0, y1] at depth z facing +z: triangles (0, 1, 2) and
// (0, 2, 3) of corners (x0, y0), (x1, y0), (x1, y1), (x0, y1).
inline void addQuad(Scene& s, float x0, float x1, float y0, float y1, float z,
                    const std::string& name) {
  Object o;
  o.name = name;
  o.material = 0;
  o.mesh.positions = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  o.mesh.normals.assign(4, glm::vec3(0.0f, 0.0f, 1.0f));
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(o);
}

// The big quad of the tests: [-10, 12] x [-10, 10] at depth z. Its diagonal passes below
// the origin, which lies inside its second triangle (-10,-10), (12,10), (-10,10).
inline void addBigQuad(Scene& s, float z, const std::string& name) {
  addQuad(s, -10.0f, 12.0f, -10.0f, 10.0f, z, name);
}

inline Light pointLight(const glm::dvec3& position) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  return l;
}

inline Light directionalLight(const glm::dvec3& direction) {
  Light l;
  l.type = LightType::Directional;
  l.direction = direction;
  return l;
}

}  // namespace rc::debugtest
