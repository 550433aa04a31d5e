// Scenes built in code for the reference renderer's tests, the benchmarks of both
// renderers (bench_reference and bench_gl render the very same scenes) and the
// cross-optimisation-level dump tools. Library rc_scene_builders: depends on the scene
// model only (no loader, no renderer).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc::test {

// A width x height scene whose orthographic camera maps world (x, y) to GL window
// (x, y) exactly for power-of-two sizes, and world z to window depth 1 - z (camera at
// z = 1 looking down -z, near 0, far 1). Default state, no lights, ambient light 1,
// one white material with ambient 1 (so untextured colour = (1, 1, 1, opacity)).
Scene windowScene(int width, int height);

// Appends an object with inline triangles; every normal is `normal`; uvs optional.
// Returns the object's index.
std::size_t addMesh(Scene& scene, const std::vector<glm::vec3>& positions,
                    const std::vector<std::array<std::uint32_t, 3>>& triangles,
                    std::size_t material = 0, const glm::vec3& normal = {0.0f, 0.0f, 1.0f},
                    const std::vector<glm::vec2>& uvs = {});

// One triangle (three fresh vertices).
std::size_t addTriangle(Scene& scene, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                        std::size_t material = 0);

// An axis-aligned rectangle at depth z as two counter-clockwise triangles, uvs (0,0)..(1,1).
std::size_t addRect(Scene& scene, float x0, float y0, float x1, float y1, float z,
                    std::size_t material = 0);

std::size_t addMaterial(Scene& scene, const Material& material);

// A UV sphere of radius 1 (normals = positions), `segments` around, `rings` pole to pole.
Mesh sphereMesh(int segments, int rings);

// Named scenes that exercise every feature (shading modes, textures, clipping, culling,
// blending, painter's, every depth and colour format): the determinism corpus.
struct NamedScene {
  std::string name;
  Scene scene;
};
std::vector<NamedScene> featureScenes();

// The pixel channels of a frame as raw bytes (colour, depth, id, every uncertainty channel),
// for bit-exact comparisons.
std::string frameBytes(const Frame& frame);

// ---- benchmark scenes (bench/reference, bench/gl) ----------------------------------------

// `count` right triangles with 2-pixel legs (area 2 px^2: about two fragments each) at
// pseudo-random positions in a size x size window scene, flat shaded, one material, depths
// cycling through 97 values in [0.25, 0.75). Setup-bound: measures triangles per second.
Scene smallTrianglesScene(int size = 1024, int count = 100000);

// The same number of triangles of the same size as one mesh, the way a finely tessellated
// model arrives: a grid of 2 x 2 px cells, each split into two triangles, every inner vertex
// shared by six triangles (about count / 2 vertices), centred in the size x size window, its
// depth a gentle slope in [0.25, 0.75], flat shaded. Every fragment passes.
Scene smallTriangleMeshScene(int size = 1024, int count = 100000);

// `layers` rectangles one pixel larger than the size x size window on every side, drawn
// back to front (z = 0.1, 0.2, ...; every fragment passes the depth test and is shaded and
// written), lit by one point light at (300, 700, 400) * size / 1024, ambient 0.1, Blinn-Phong
// specular 0.5 with shininess 32. Fragment-bound: measures fragments per second
// (layers * size^2 fragments per frame).
Scene layersScene(Shading shading, int size = 1024, int layers = 8);

// `count` segments with pseudo-random ends 2 to 60 px apart (every third drawn 3 px wide,
// the rest one pixel) and `count` points of size 3, in a size x size window scene, Gouraud
// with one point light, depths in [0.25, 0.75): lines and points at scale.
Scene linesScene(int size = 1024, int count = 20000);
// A teapot on a floor lit by a directional light through a size x size d24 shadow map
// (front faces culled in the map pass), nearest lookups on the teapot and PCF on the floor:
// the multi-pass path, size x 3/4 size, Phong.
Scene shadowScene(int size = 1024);

}  // namespace rc::test
