// Helpers for the GL backend tests: the spec under test (one per process, from
// RASTERCHECK_GL_SPEC), the skip-or-fail rule when no driver starts, and small scenes
// built in code (no loader).
#pragma once

#include <cstdlib>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "fixtures/errors.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "gl_backend/gl_backend.h"

namespace rc::gltest {

// The spec this process tests; CTest registers the binary once per driver.
inline std::string specText() {
  const char* env = std::getenv("RASTERCHECK_GL_SPEC");
  return env != nullptr && *env != '\0' ? env : "gl:egl:llvmpipe";
}
inline GlSpec spec() { return parseGlSpec(specText()); }

inline bool requireGl() {
  const char* env = std::getenv("RASTERCHECK_REQUIRE_GL");
  return env != nullptr && std::string(env) == "1";
}

// Orthographic camera looking down -z from (0,0,2); bounds [-1,1]^2, near 1, far 3, so
// world z maps to window depth 0.5 - z/2 and world (x, y) to pixel centres linearly.
inline Scene orthoScene(int width, int height) {
  Scene s;
  s.name = "gltest/ortho";
  s.width = width;
  s.height = height;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 2.0};
  s.camera.target = {0.0, 0.0, 0.0};
  s.camera.up = {0.0, 1.0, 0.0};
  s.camera.bounds = {-1.0, 1.0, -1.0, 1.0};
  s.camera.near = 1.0;
  s.camera.far = 3.0;
  return s;
}

inline std::size_t addMaterial(Scene& s, Material m) {
  s.materials.push_back(std::move(m));
  return s.materials.size() - 1;
}

// A z-constant rectangle [x0,x1]x[y0,y1] at world z, two triangles (0,1,2) and (0,2,3)
// counter-clockwise seen from +z, normals +z, uvs from (u0,v0) to (u1,v1).
inline Object quad(double x0, double y0, double x1, double y1, double z, std::size_t material,
                   glm::vec2 uv0 = {0, 0}, glm::vec2 uv1 = {1, 1}) {
  Object o;
  o.name = "quad";
  o.material = material;
  const auto fx0 = static_cast<float>(x0), fx1 = static_cast<float>(x1);
  const auto fy0 = static_cast<float>(y0), fy1 = static_cast<float>(y1);
  const auto fz = static_cast<float>(z);
  o.mesh.positions = {{fx0, fy0, fz}, {fx1, fy0, fz}, {fx1, fy1, fz}, {fx0, fy1, fz}};
  o.mesh.normals.assign(4, glm::vec3(0, 0, 1));
  o.mesh.uvs = {{uv0.x, uv0.y}, {uv1.x, uv0.y}, {uv1.x, uv1.y}, {uv0.x, uv1.y}};
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return o;
}

// World (x, y) of the centre of image pixel (px, py) (row 0 on top) in orthoScene.
inline glm::dvec2 pixelCentreWorld(const Scene& s, int px, int py) {
  const double x = -1.0 + 2.0 * (px + 0.5) / s.width;
  const double y = -1.0 + 2.0 * ((s.height - 1 - py) + 0.5) / s.height;
  return {x, y};
}

inline glm::dvec4 colorAt(const Frame& f, int x, int y) {
  const std::size_t i = f.index(x, y) * 4;
  return {f.color[i], f.color[i + 1], f.color[i + 2], f.color[i + 3]};
}

}  // namespace rc::gltest

namespace rc::gltest {

// Base fixture: skips (or, with RASTERCHECK_REQUIRE_GL=1, fails) when the process's
// spec cannot start, probing once per process with a 1x1 scene.
class GlTest : public ::testing::Test {
 public:
  static Frame render(const Scene& s) { return renderGl(s, spec()); }

 protected:
  void SetUp() override {
    static const std::optional<std::string> failure = probe();
    if (failure) {
      if (requireGl()) FAIL() << "RASTERCHECK_REQUIRE_GL=1 but " << specText() << ": " << *failure;
      GTEST_SKIP() << "no GL driver starts for " << specText() << ": " << *failure;
    }
  }

 private:
  static std::optional<std::string> probe() {
    try {
      renderGl(orthoScene(1, 1), spec());
      return std::nullopt;
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
  }
};

}  // namespace rc::gltest
