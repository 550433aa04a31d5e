// Building the vertex buffer: see vertex_data.h.
#include "gl_backend/vertex_data.h"

#include <cmath>
#include <limits>

#include "fixtures/scene_geometry.h"

namespace rc::gl {
namespace {

// World-space attributes of one object's vertices, computed once per object.
struct WorldMesh {
  std::vector<glm::dvec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<bool> finite;  // world and clip position finite, in double and in float
};

bool isFinite(const glm::dvec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

bool fitsFloat(const glm::dvec3& v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  return std::abs(v.x) <= kMax && std::abs(v.y) <= kMax && std::abs(v.z) <= kMax;
}

WorldMesh toWorld(const Object& o, const glm::dmat4& view_projection, bool model_matrix_normals) {
  WorldMesh w;
  const std::size_t n = o.mesh.positions.size();
  w.positions.resize(n);
  w.normals.resize(n);
  w.finite.resize(n);
  // The fault no_inverse_transpose: the classic mistake, exact only for rotations and
  // uniform scales.
  const glm::dmat3 normal_matrix =
      model_matrix_normals ? glm::dmat3(o.model) : normalMatrix(o.model);
  for (std::size_t i = 0; i < n; ++i) {
    w.positions[i] = worldPosition(o.model, o.mesh.positions[i]);
    // The reference drops a triangle whose clip position is not finite; the GPU also
    // needs the world position as finite floats (fitsFloat is false for inf and NaN).
    w.finite[i] =
        fitsFloat(w.positions[i]) && isFinite(view_projection * glm::dvec4(w.positions[i], 1.0));
    w.normals[i] = glm::vec3(worldNormal(normal_matrix, o.mesh.normals[i]));
  }
  return w;
}

void store(float (&dst)[3], const glm::dvec3& v) {
  dst[0] = static_cast<float>(v.x);
  dst[1] = static_cast<float>(v.y);
  dst[2] = static_cast<float>(v.z);
}

// The fault move_vertex: `world` moved one pixel right in window space (NDC x + 2/width
// at the same clip w, so the same depth and the same pixel row), back in world space.
glm::dvec3 onePixelRight(const glm::dvec3& world, const glm::dmat4& view_projection, int width) {
  glm::dvec4 clip = view_projection * glm::dvec4(world, 1.0);
  clip.x += 2.0 / width * clip.w;
  const glm::dvec4 back = glm::inverse(view_projection) * clip;
  return glm::dvec3(back) / back.w;
}

// The fault move_line_end: `world` (a segment's end) moved one pixel in the segment's minor
// window direction (y when the segment from `start` is x-major, else x), same clip w.
glm::dvec3 onePixelAcross(const glm::dvec3& start, const glm::dvec3& world,
                          const glm::dmat4& view_projection, int width, int height) {
  const glm::dvec4 a = view_projection * glm::dvec4(start, 1.0);
  glm::dvec4 clip = view_projection * glm::dvec4(world, 1.0);
  const double dx = (clip.x / clip.w - a.x / a.w) * width;
  const double dy = (clip.y / clip.w - a.y / a.w) * height;
  if (std::abs(dx) >= std::abs(dy)) {
    clip.y += 2.0 / height * clip.w;
  } else {
    clip.x += 2.0 / width * clip.w;
  }
  const glm::dvec4 back = glm::inverse(view_projection) * clip;
  return glm::dvec3(back) / back.w;
}

}  // namespace

VertexData buildVertexData(const Scene& scene, const std::vector<DrawPass>& passes,
                           const testing::Faults& faults) {
  validateForRendering(scene);  // every index below is in range after this
  const glm::dmat4 view_projection = viewProjectionMatrix(scene);
  std::vector<WorldMesh> world;
  world.reserve(scene.objects.size());
  for (const Object& o : scene.objects)
    world.push_back(toWorld(o, view_projection, faults.no_inverse_transpose));

  VertexData data;
  std::size_t triangles = 0;
  for (const DrawPass& p : passes) triangles += p.primitives.size();
  data.vertices.reserve(triangles * 3);

  for (const DrawPass& pass : passes) {
    PassRuns& out = data.passes.emplace_back();
    out.depth_func = pass.depth_func;
    out.depth_write = pass.depth_write;
    out.blend = pass.blend;
    out.state = pass;
    out.state.primitives.clear();
    for (const PrimitiveRef& prim : pass.primitives) {
      if (prim.id == faults.drop_primitive) continue;  // the fault drop_primitive=ID
      const Object& obj = scene.objects[prim.object];
      const WorldMesh& wm = world[prim.object];
      std::uint32_t tri[3];
      const int count = primitiveVertices(obj, prim.triangle, tri);
      bool finite = true;
      for (int k = 0; k < count; ++k) finite = finite && wm.finite[tri[k]];
      if (!finite) {
        ++data.skipped_triangles;
        continue;
      }
      FlatFace face;
      if (count == 3) {
        face = flatFace(wm.positions[tri[0]], wm.positions[tri[1]], wm.positions[tri[2]]);
      } else {
        const std::uint32_t last = tri[count - 1];
        face = flatSegment(wm.positions[tri[0]], wm.positions[last], glm::dvec3(wm.normals[tri[0]]),
                           glm::dvec3(wm.normals[last]));
      }

      const auto material = static_cast<std::uint32_t>(obj.material);
      const auto first = static_cast<std::uint32_t>(data.vertices.size());
      if (out.runs.empty() || out.runs.back().material != material)
        out.runs.push_back(DrawRun{material, first, 0});
      out.runs.back().vertex_count += static_cast<std::uint32_t>(count);

      for (int k = 0; k < count; ++k) {
        const std::uint32_t vi = tri[k];
        Vertex& v = data.vertices.emplace_back();
        // The fault move_vertex=ID: only this triangle's first vertex (the buffer is
        // unindexed, so the triangles sharing it keep theirs); lighting and the flat
        // centroid stay where they were, so the error is geometry alone. move_line_end and
        // move_point likewise for a segment's second vertex and a point.
        glm::dvec3 position = wm.positions[vi];
        const bool moved_right = (k == 0 && count == 3 && prim.id == faults.move_vertex) ||
                                 (k == 0 && count == 1 && prim.id == faults.move_point);
        if (moved_right) {
          position = onePixelRight(position, view_projection, scene.width);
        } else if (k == 1 && count == 2 && prim.id == faults.move_line_end) {
          position = onePixelAcross(wm.positions[tri[0]], position, view_projection, scene.width,
                                    scene.height);
        }
        store(v.world_position, position);
        const glm::vec3& n = wm.normals[vi];
        v.world_normal[0] = n.x;
        v.world_normal[1] = n.y;
        v.world_normal[2] = n.z;
        const glm::vec2 uv = obj.mesh.uvs.empty() ? glm::vec2(0.0f) : obj.mesh.uvs[vi];
        v.uv[0] = uv.x;
        v.uv[1] = uv.y;
        v.primitive_id = prim.id;
        store(v.face_centroid, face.centroid);
        store(v.face_normal, face.normal);
      }
    }
    if (out.runs.empty()) data.passes.pop_back();
  }
  return data;
}

}  // namespace rc::gl
