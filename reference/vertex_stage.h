// Vertex stage: object -> world -> clip space, in double, with the matrices of
// fixtures/scene_logic.h (never re-derived here). It does not clip, cull or light.
#pragma once

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
  glm::dvec3 normal{0.0};  // safeNormalize(normalMatrix(model) * normal): zero stays zero
  glm::dvec4 clip{0.0};    // view_projection * world
  glm::dvec2 uv{0.0};      // (0, 0) when the mesh has no uvs (as the GL backend feeds)
};

// Transforms every vertex of the object (non-finite input gives non-finite output;
// the renderer drops such triangles). Without `normals` (flat shading lights the face
// normal, never a vertex normal) TransformedVertex::normal is left zero.
void transformObject(const Object& object, const CameraTransform& camera,
                     std::vector<TransformedVertex>& out, bool normals = true);

}  // namespace rc::ref
