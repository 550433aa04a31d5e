// Vertex stage: see vertex_stage.h.
#include "reference/vertex_stage.h"

#include "fixtures/scene_geometry.h"
#include "fixtures/scene_logic.h"

namespace rc::ref {

CameraTransform cameraTransform(const Scene& scene) {
  CameraTransform t;
  t.view_projection = viewProjectionMatrix(scene);
  t.eye = scene.camera.eye;
  return t;
}

void transformObject(const Object& object, const CameraTransform& camera,
                     std::vector<TransformedVertex>& out, bool normals, bool errors) {
  const Mesh& mesh = object.mesh;
  const glm::dmat3 normal_matrix = normalMatrix(object.model);
  glm::dmat4 abs_vp(0.0);
  for (int c = 0; c < 4; ++c) abs_vp[c] = glm::abs(camera.view_projection[c]);
  out.resize(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    TransformedVertex& v = out[i];
    v.world = worldPosition(object.model, mesh.positions[i]);
    v.clip = camera.view_projection * glm::dvec4(v.world, 1.0);
    v.normal = normals && i < mesh.normals.size() ? worldNormal(normal_matrix, mesh.normals[i])
                                                  : glm::dvec3(0.0);
    v.uv = i < mesh.uvs.size() ? glm::dvec2(mesh.uvs[i]) : glm::dvec2(0.0);
    if (errors)
      v.clip_err = (kClipRoundingUlps * kUlp32) * (abs_vp * glm::dvec4(glm::abs(v.world), 1.0));
  }
}

}  // namespace rc::ref
