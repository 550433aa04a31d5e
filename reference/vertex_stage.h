// Vertex stage: object -> world -> clip space, in double, with the matrices of
// fixtures/scene_logic.h (never re-derived here). It does not clip, cull or light.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "fixtures/scene.h"

namespace rc::ref {

// The camera as the vertex stage and the lighting need it.
struct CameraTransform {
  glm::dmat4 view_projection{1.0};  // projectionMatrix(camera, W/H) * viewMatrix(camera)
  glm::dvec3 eye{0.0};              // the viewer position for lighting (camera.eye)
};

CameraTransform cameraTransform(const Scene& scene);

// One mesh vertex after the vertex stage.
struct TransformedVertex {
  glm::dvec3 world{0.0};   // model * position
  glm::dvec3 normal{0.0};  // worldNormal(normalMatrix(model), normal): zero stays zero
  glm::dvec4 clip{0.0};    // view_projection * world
  glm::dvec2 uv{0.0};      // (0, 0) when the mesh has no uvs (as the GL backend feeds)
  // How far a float32 implementation's clip coordinates may be from `clip`, per
  // component: kClipRoundingUlps ulps of the magnitudes the product sums,
  // |view_projection| * (|world|, 1) (the world position reaches GL as floats and the
  // matrix as a float uniform). Only with `errors` (the uncertainty channels need it).
  glm::dvec4 clip_err{0.0};
};

// Roundings of a float32 vertex transform: the world position and the matrix entries
// rounded to float, four products and three sums per component: 8 ulps (2^-21) of the sum
// of the terms' magnitudes bounds it (docs/tolerances.md, "Vertex precision").
inline constexpr double kClipRoundingUlps = 8.0;
inline constexpr double kUlp32 = 0x1p-24;  // float32 unit roundoff

// Transforms every vertex of the object (non-finite input gives non-finite output;
// the renderer drops such triangles). Without `normals` (flat shading lights the face
// normal, never a vertex normal) TransformedVertex::normal is left zero.
// The vertices' world, clip and clip_err are computed four matrix rows a vector, each lane the
// IEEE operation GLM's mat4 * vec4 does, (m0 x + m1 y) + (m2 z + m3 w): bit for bit
// worldPosition() and view_projection * (world, 1).
void transformObject(const Object& object, const CameraTransform& camera,
                     std::vector<TransformedVertex>& out, bool normals = true, bool errors = false);

// transformObject() prepared once for an object and applied to ranges of its vertices:
// the renderer transforms an object in pieces and sets up each piece's window positions
// while its vertices are still in the cache (a soup of 300k vertices is 38 MB of them).
// Each vertex gets the bits transformObject() gives it.
class ObjectTransform {
 public:
  ObjectTransform(const Object& object, const CameraTransform& camera, bool normals = true,
                  bool errors = false);
  // Vertices [begin, end) of the object into out[begin, end).
  void apply(std::size_t begin, std::size_t end, TransformedVertex* out) const {
    applyInto(begin, end, out + begin);
  }
  // Vertices [begin, end) of the object into first[0, end - begin) (a buffer for one piece).
  void applyInto(std::size_t begin, std::size_t end, TransformedVertex* first) const;

 private:
  const Object* object_;
  const CameraTransform* camera_;
  glm::dmat4 abs_vp_;
  glm::dmat3 normal_matrix_;
  bool with_normals_;
  bool errors_;
};

// The definition of the positions' part of one vertex (world, clip and, with `errors`,
// clip_err; normal and uv left zero), scalar and in GLM's own operations: what the vector
// builds below compute four matrix rows at a time. The renderer does not call it; the tests
// hold both builds equal to it bit for bit (tests/reference/test_vertex_stage.cpp).
TransformedVertex transformPositionDefinition(const glm::dmat4& model,
                                              const glm::dmat4& view_projection,
                                              const glm::dmat4& abs_vp, const glm::vec3& position,
                                              bool errors);

namespace detail {
// The two builds transformObject() chooses between for the positions' part (world, clip,
// clip_err; abs_vp: |view_projection| per entry), for the tests to run each (the AVX2 one
// only where the CPU has AVX2).
void transformPositionsBaseline(const glm::dmat4& model, const glm::dmat4& view_projection,
                                const glm::dmat4& abs_vp, const glm::vec3* positions,
                                std::size_t count, TransformedVertex* out, bool errors);
void transformPositionsAvx2(const glm::dmat4& model, const glm::dmat4& view_projection,
                            const glm::dmat4& abs_vp, const glm::vec3* positions, std::size_t count,
                            TransformedVertex* out, bool errors);
}  // namespace detail

}  // namespace rc::ref
