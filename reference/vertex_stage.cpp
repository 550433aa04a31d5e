// Vertex stage: see vertex_stage.h.
#include "reference/vertex_stage.h"

#include "fixtures/scene_geometry.h"
#include "fixtures/scene_logic.h"
#include "reference/lanes.h"

namespace rc::ref {

CameraTransform cameraTransform(const Scene& scene) {
  CameraTransform t;
  t.view_projection = viewProjectionMatrix(scene);
  t.eye = scene.camera.eye;
  return t;
}

TransformedVertex transformPositionDefinition(const glm::dmat4& model,
                                              const glm::dmat4& view_projection,
                                              const glm::dmat4& abs_vp, const glm::vec3& position,
                                              bool errors) {
  TransformedVertex v;
  v.world = worldPosition(model, position);
  v.clip = view_projection * glm::dvec4(v.world, 1.0);
  if (errors)
    v.clip_err = (kClipRoundingUlps * kUlp32) * (abs_vp * glm::dvec4(glm::abs(v.world), 1.0));
  return v;
}

namespace {

// Lane4 values stay inside transformPositions() (everything it calls on them is inlined):
// -Wpsabi's note on passing 32-byte vectors without AVX does not apply (for the rest of the
// file: GCC also gives it at the end of the translation unit).
#pragma GCC diagnostic ignored "-Wpsabi"

struct Columns {
  Lane4 c[4];
};

[[gnu::always_inline]] inline Columns columnsOf(const glm::dmat4& m) {
  Columns out;
  for (int k = 0; k < 4; ++k) out.c[k] = Lane4{m[k].x, m[k].y, m[k].z, m[k].w};
  return out;
}

// m * (x, y, z, 1) as GLM's mat4 * vec4 computes it, (m0 x + m1 y) + (m2 z + m3 1), each
// product and sum the same IEEE operation in each lane: worldPosition() and the clip
// transform's bits.
[[gnu::always_inline]] inline Lane4 transform4(const Columns& m, double x, double y, double z) {
  return (m.c[0] * splat4(x) + m.c[1] * splat4(y)) + (m.c[2] * splat4(z) + m.c[3] * splat4(1.0));
}

// glm::abs() of a double: x >= 0 ? x : -x (it keeps -0 and flips the sign of a NaN, where
// std::fabs clears both).
[[gnu::always_inline]] inline double glmAbs(double x) { return x >= 0.0 ? x : -x; }

// The positions' part of transformObject(): world, clip and (with `errors`) clip_err of
// every vertex, four matrix rows a vector. The body of both builds below.
[[gnu::always_inline]] inline void transformLanes(const glm::dmat4& model,
                                                  const glm::dmat4& view_projection,
                                                  const glm::dmat4& abs_vp,
                                                  const glm::vec3* positions, std::size_t count,
                                                  TransformedVertex* out, bool errors) {
  const Columns m = columnsOf(model);
  const Columns vp = columnsOf(view_projection);
  const Columns avp = columnsOf(abs_vp);
  const Lane4 ulps = splat4(kClipRoundingUlps * kUlp32);
  for (std::size_t i = 0; i < count; ++i) {
    const glm::dvec3 p(positions[i]);
    const Lane4 world = transform4(m, p.x, p.y, p.z);
    const Lane4 clip = transform4(vp, world[0], world[1], world[2]);
    TransformedVertex& v = out[i];
    v.world = glm::dvec3(world[0], world[1], world[2]);
    v.clip = glm::dvec4(clip[0], clip[1], clip[2], clip[3]);
    if (errors) {
      const Lane4 e = ulps * transform4(avp, glmAbs(world[0]), glmAbs(world[1]), glmAbs(world[2]));
      v.clip_err = glm::dvec4(e[0], e[1], e[2], e[3]);
    } else {
      v.clip_err = glm::dvec4(0.0);
    }
  }
}

}  // namespace

namespace detail {
void transformPositionsBaseline(const glm::dmat4& model, const glm::dmat4& view_projection,
                                const glm::dmat4& abs_vp, const glm::vec3* positions,
                                std::size_t count, TransformedVertex* out, bool errors) {
  transformLanes(model, view_projection, abs_vp, positions, count, out, errors);
}
__attribute__((target("avx2"))) void transformPositionsAvx2(
    const glm::dmat4& model, const glm::dmat4& view_projection, const glm::dmat4& abs_vp,
    const glm::vec3* positions, std::size_t count, TransformedVertex* out, bool errors) {
  transformLanes(model, view_projection, abs_vp, positions, count, out, errors);
}
}  // namespace detail

ObjectTransform::ObjectTransform(const Object& object, const CameraTransform& camera, bool normals,
                                 bool errors)
    : object_(&object),
      camera_(&camera),
      abs_vp_(0.0),
      with_normals_(normals && !object.mesh.normals.empty()),
      errors_(errors) {
  for (int c = 0; c < 4; ++c) abs_vp_[c] = glm::abs(camera.view_projection[c]);
  normal_matrix_ = with_normals_ ? normalMatrix(object.model) : glm::dmat3(0.0);
}

void ObjectTransform::applyInto(std::size_t begin, std::size_t end,
                                TransformedVertex* first) const {
  const Mesh& mesh = object_->mesh;
  // x86-64's baseline or AVX2 (no FMA), whichever the CPU has: the bits are the same either
  // way (lanes.h).
  static const bool kAvx2 = __builtin_cpu_supports("avx2");
  (kAvx2 ? detail::transformPositionsAvx2 : detail::transformPositionsBaseline)(
      object_->model, camera_->view_projection, abs_vp_, mesh.positions.data() + begin, end - begin,
      first, errors_);
  for (std::size_t i = begin; i < end; ++i) {
    TransformedVertex& v = first[i - begin];
    v.normal = with_normals_ && i < mesh.normals.size()
                   ? worldNormal(normal_matrix_, mesh.normals[i])
                   : glm::dvec3(0.0);
    v.uv = i < mesh.uvs.size() ? glm::dvec2(mesh.uvs[i]) : glm::dvec2(0.0);
  }
}

void transformObject(const Object& object, const CameraTransform& camera,
                     std::vector<TransformedVertex>& out, bool normals, bool errors) {
  // Every field of every vertex is written: a vector kept from an earlier frame need not be
  // cleared first.
  out.resize(object.mesh.positions.size());
  ObjectTransform(object, camera, normals, errors).apply(0, out.size(), out.data());
}

}  // namespace rc::ref
