// The CPU side of a GL draw: the scene's triangles, in the exact order of
// fixtures/scene_logic.h drawPasses(), as one unindexed interleaved vertex buffer
// (3 vertices per triangle) plus the runs that share fixed-function state and material.
// Positions and normals are taken to world space here, in double, and rounded to float
// once; the GPU then applies only the float view-projection matrix.
#pragma once

#include <cstdint>
#include <vector>

#include "fixtures/scene.h"
#include "fixtures/scene_logic.h"
#include "gl_backend/gl_testing.h"

namespace rc::gl {

struct Vertex {
  float world_position[3];
  float world_normal[3];  // worldNormal(): unit length, or zero when it has no direction
  float uv[2];            // (0, 0) for meshes without uvs
  std::uint32_t primitive_id;
  float face_centroid[3];  // flat shading: flatFace().centroid of the original triangle
  float face_normal[3];    // flat shading: flatFace().normal, safeNormalize(cross(p1-p0, p2-p0))
};
static_assert(sizeof(Vertex) == 60, "the attribute offsets in gl_renderer.cpp assume no padding");

// Consecutive triangles of one pass drawn with one material: one glDrawArrays.
struct DrawRun {
  std::uint32_t material = 0;
  std::uint32_t first_vertex = 0;
  std::uint32_t vertex_count = 0;
};

struct PassRuns {
  DepthFunc depth_func = DepthFunc::Less;
  bool depth_write = true;
  bool blend = false;
  DrawPass state;  // the pass's whole fixed-function state (its primitives left out)
  std::vector<DrawRun> runs;
};

struct VertexData {
  std::vector<Vertex> vertices;
  std::vector<PassRuns> passes;
  std::size_t skipped_triangles = 0;  // dropped for non-finite positions (as the reference does)
};

// Builds the buffer for drawPasses(scene). World positions, normals and the flat
// centroid and face normal are the shared ones (fixtures/scene_geometry.h: worldPosition,
// worldNormal, flatFace), as the reference computes them. Triangles with a non-finite clip
// position, or a world position that does not fit a float, are left out; their ids stay
// unused. Throws InputError for what validateForRendering() (fixtures/scene_logic.h)
// rejects.
// Of the test-only faults, drop_primitive, move_vertex and no_inverse_transpose act here.
VertexData buildVertexData(const Scene& scene, const std::vector<DrawPass>& passes,
                           const testing::Faults& faults = {});

}  // namespace rc::gl
