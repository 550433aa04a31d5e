// GLSL sources: see shaders.h. Written next to DESIGN.md "Shading"; every formula below
// has a same-named counterpart in reference/shading.cpp.
#include "gl_backend/shaders.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "fixtures/scene.h"

namespace rc::gl {

const std::vector<GlslEnumDefine>& glslEnumDefines() {
  static const std::vector<GlslEnumDefine> defines = [] {
    std::vector<GlslEnumDefine> out;
    // RC_<PREFIX>_<the fixture-file name of the value, upper case, '-' as '_'>.
    auto add = [&](const char* prefix, const char* value_name, int value) {
      std::string name = fmt::format("RC_{}_{}", prefix, value_name);
      std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) {
        return c == '-' ? '_' : static_cast<char>(std::toupper(c));
      });
      out.push_back({name, value});
    };
    for (Shading v : {Shading::Flat, Shading::Gouraud, Shading::Phong})
      add("SHADING", toString(v), uniformValue(v));
    for (SpecularModel v : {SpecularModel::Phong, SpecularModel::BlinnPhong})
      add("SPECULAR", toString(v), uniformValue(v));
    for (Attenuation v : {Attenuation::None, Attenuation::Inverse, Attenuation::InverseSquare})
      add("ATTENUATION", toString(v), uniformValue(v));
    add("LIGHT", "point", uniformValue(LightType::Point));
    add("LIGHT", "directional", uniformValue(LightType::Directional));
    return out;
  }();
  return defines;
}

namespace {

constexpr const char* kHeader = R"(#version 330 core
#define RC_MAX_LIGHTS {}
)";

// Uniforms and the lighting model, shared by both stages (flat and Gouraud light per
// vertex, Phong per fragment).
constexpr const char* kLighting = R"(
uniform vec3 u_eye;               // camera.eye: v points towards it
uniform vec3 u_ambient_light;
uniform int u_light_count;
uniform int u_light_type[RC_MAX_LIGHTS];         // RC_LIGHT_POINT or RC_LIGHT_DIRECTIONAL
uniform vec3 u_light_position[RC_MAX_LIGHTS];    // point lights, world space
uniform vec3 u_light_direction[RC_MAX_LIGHTS];   // directional: the direction light travels
uniform vec3 u_light_color[RC_MAX_LIGHTS];
uniform float u_light_intensity[RC_MAX_LIGHTS];
uniform int u_specular_model;     // RC_SPECULAR_PHONG or RC_SPECULAR_BLINN_PHONG
uniform int u_attenuation;        // RC_ATTENUATION_NONE, _INVERSE (1/r), _INVERSE_SQUARE (1/r^2)
uniform vec3 u_material_ambient;
uniform vec3 u_material_diffuse;
uniform vec3 u_material_specular;
uniform float u_shininess;

#ifdef RC_SHADOW_LOOKUP
// Shadow lookups (fragment stage): the material's map through a sampler2DShadow (compare
// mode, function and filter set on the texture), u_light_shadowed[i] for the lights whose
// map it is; behind the map's camera (w <= 0) the light is not shadowed.
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_shadow_matrix;  // world -> the map's (s, t, r, w), composed in double
uniform float u_shadow_bias;
uniform int u_light_shadowed[RC_MAX_LIGHTS];
#ifdef RC_FAULT_SHADOW_SHIFT
uniform float u_fault_shadow_shift;  // test-only: map texels to the right
#endif
float shadowFactor(int i, vec3 p) {
  if (u_light_shadowed[i] == 0) return 1.0;
  vec4 c = u_shadow_matrix * vec4(p, 1.0);
  if (!(c.w > 0.0)) return 1.0;
  vec3 q = c.xyz / c.w;
#ifdef RC_FAULT_SHADOW_SHIFT
  q.x += u_fault_shadow_shift / float(textureSize(u_shadow_map, 0).x);
#endif
  return texture(u_shadow_map, vec3(q.xy, q.z - u_shadow_bias));
}
#endif

// normalize() with zero (or a non-finite length) staying zero: a zero normal lights nothing.
vec3 safeNormalize(vec3 v) {
  float len = length(v);
  return (len > 0.0 && !isinf(len)) ? v / len : vec3(0.0);
}

// max(0, x)^s with pow(0, 0) := 1 (GLSL leaves pow(0, y <= 0) undefined).
float specularPower(float base, float shininess) {
  if (shininess == 0.0) return 1.0;
  return base > 0.0 ? pow(base, shininess) : 0.0;
}

// The lit colour at world point p with unit normal n, split into the part a texture
// multiplies (ambient + sum of diffuse) and the part it does not (sum of specular).
void shadePoint(vec3 p, vec3 n, out vec3 ambient_diffuse, out vec3 specular) {
  ambient_diffuse = u_material_ambient * u_ambient_light;
  specular = vec3(0.0);
  if (n == vec3(0.0)) return;  // zero normal: no diffuse, no specular
  vec3 v = safeNormalize(u_eye - p);
  for (int i = 0; i < u_light_count; ++i) {
    vec3 l;
    float att = 1.0;
    if (u_light_type[i] == RC_LIGHT_DIRECTIONAL) {
      l = -safeNormalize(u_light_direction[i]);
    } else {
      vec3 to_light = u_light_position[i] - p;
      float r = length(to_light);
      if (!(r > 0.0)) continue;  // light at the shaded point: contributes nothing
      l = to_light / r;
      if (u_attenuation == RC_ATTENUATION_INVERSE) att = 1.0 / r;
      else if (u_attenuation == RC_ATTENUATION_INVERSE_SQUARE) att = 1.0 / (r * r);
    }
    vec3 L = u_light_color[i] * u_light_intensity[i] * att;
    float n_dot_l = dot(n, l);
#ifndef RC_SHADOW_LOOKUP
    ambient_diffuse += u_material_diffuse * L * max(0.0, n_dot_l);
#endif
    float base;
    if (u_specular_model == RC_SPECULAR_BLINN_PHONG) {
      vec3 h = safeNormalize(l + v);
      base = max(0.0, dot(n, h));
    } else {
      vec3 r = 2.0 * n_dot_l * n - l;
      base = max(0.0, dot(r, v));
    }
#ifdef RC_SHADOW_LOOKUP
    // The lookup's result scales this light's terms (1 for lights the material's map does
    // not belong to): reference/shading.h shadePrepared().
    float f = shadowFactor(i, p);
    ambient_diffuse += (u_material_diffuse * L * max(0.0, n_dot_l)) * f;
    specular += (u_material_specular * L * specularPower(base, u_shininess)) * f;
#else
    specular += u_material_specular * L * specularPower(base, u_shininess);
#endif
  }
}
)";

constexpr const char* kVertexMain = R"(
layout(location = 0) in vec3 a_world_position;
layout(location = 1) in vec3 a_world_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in uint a_primitive_id;
layout(location = 4) in vec3 a_face_centroid;
layout(location = 5) in vec3 a_face_normal;

uniform mat4 u_view_projection;  // projection * view, composed in double on the CPU
uniform int u_shading;           // RC_SHADING_FLAT, _GOURAUD or _PHONG
#ifdef RC_FAULT_SHIFT_X
uniform float u_fault_shift_ndc;  // test-only: 2 * PX / width
#endif

out vec3 v_world_position;
out vec3 v_world_normal;
out vec2 v_uv;
out vec3 v_gouraud_ambient_diffuse;
out vec3 v_gouraud_specular;
flat out uint v_primitive_id;
// Flat: every vertex of a triangle carries the same centroid and face normal, so each
// computes the same colour and the provoking vertex's is used for the whole triangle:
// lit once per vertex instead of once per fragment.
flat out vec3 v_flat_ambient_diffuse;
flat out vec3 v_flat_specular;

void main() {
  gl_Position = u_view_projection * vec4(a_world_position, 1.0);
#ifdef RC_FAULT_SHIFT_X
  gl_Position.x += u_fault_shift_ndc * gl_Position.w;  // NDC x + 2 PX / width
#endif
  v_world_position = a_world_position;
  v_world_normal = a_world_normal;
  v_uv = a_uv;
  v_primitive_id = a_primitive_id;
  v_gouraud_ambient_diffuse = vec3(0.0);
  v_gouraud_specular = vec3(0.0);
  v_flat_ambient_diffuse = vec3(0.0);
  v_flat_specular = vec3(0.0);
  if (u_shading == RC_SHADING_FLAT)
    shadePoint(a_face_centroid, a_face_normal, v_flat_ambient_diffuse, v_flat_specular);
  if (u_shading == RC_SHADING_GOURAUD)
    shadePoint(a_world_position, a_world_normal, v_gouraud_ambient_diffuse, v_gouraud_specular);
}
)";

constexpr const char* kFragmentMain = R"(
in vec3 v_world_position;
in vec3 v_world_normal;
in vec2 v_uv;
in vec3 v_gouraud_ambient_diffuse;
in vec3 v_gouraud_specular;
flat in uint v_primitive_id;
flat in vec3 v_flat_ambient_diffuse;
flat in vec3 v_flat_specular;

uniform int u_shading;
uniform int u_has_texture;
uniform sampler2D u_texture;
uniform float u_opacity;
#ifdef RC_FAULT_DEPTH_BIAS
uniform float u_fault_depth_bias;  // test-only: STEPS / (2^bits - 1)
#endif
#ifdef RC_FAULT_TEXEL_OFFSET
uniform float u_fault_texel_offset;  // test-only: texels to the right
#endif
#ifdef RC_FAULT_LOD_WEIGHT
uniform float u_fault_lod_bias;  // test-only: the texture's GL_TEXTURE_LOD_BIAS
#endif

layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_primitive_id;

void main() {
#ifdef RC_FAULT_TEXEL_OFFSET
  vec2 texel = vec2(1.0 / vec2(textureSize(u_texture, 0)));
  vec2 uv = v_uv + vec2(u_fault_texel_offset * texel.x, 0.0);
  vec3 tex = u_has_texture != 0 ? texture(u_texture, uv).rgb : vec3(1.0);
#else
  vec3 tex = u_has_texture != 0 ? texture(u_texture, v_uv).rgb : vec3(1.0);
#endif
#ifdef RC_FAULT_LOD_WEIGHT
  // Between two levels, the blend weight inverted: (1 - f) of the finer level and f of the
  // coarser instead of the reverse. textureQueryLOD's x is the clamped level of detail the
  // lookup above used; it is fractional only where two levels are blended. textureLod adds
  // the texture's bias to its level, so the bias is taken off first.
  if (u_has_texture != 0) {
    float lod = textureQueryLOD(u_texture, v_uv).x;  // the ARB extension's spelling
    float finer = floor(lod);
    float f = lod - finer;
    if (f > 0.0)
      tex = mix(textureLod(u_texture, v_uv, finer - u_fault_lod_bias).rgb,
                textureLod(u_texture, v_uv, finer + 1.0 - u_fault_lod_bias).rgb, 1.0 - f);
  }
#endif
  vec3 ambient_diffuse;
  vec3 specular;
  if (u_shading == RC_SHADING_FLAT) {
    ambient_diffuse = v_flat_ambient_diffuse;
    specular = v_flat_specular;
  } else if (u_shading == RC_SHADING_GOURAUD) {
    ambient_diffuse = v_gouraud_ambient_diffuse;
    specular = v_gouraud_specular;
  } else {
    shadePoint(v_world_position, safeNormalize(v_world_normal), ambient_diffuse, specular);
  }
  o_color = vec4(tex * ambient_diffuse + specular, u_opacity);
  o_primitive_id = v_primitive_id;
#ifdef RC_FAULT_DEPTH_BIAS
  gl_FragDepth = gl_FragCoord.z + u_fault_depth_bias;
#endif
#ifdef RC_FAULT_COMPILE_ERROR
  rc_injected_compile_error();
#endif
}
)";

}  // namespace

ProgramSource programSource(int max_lights, const ShaderFaults& faults, bool shadows) {
  std::string header = fmt::format(kHeader, max_lights);
  for (const GlslEnumDefine& d : glslEnumDefines())
    header += fmt::format("#define {} {}\n", d.name, d.value);
  if (faults.depth_bias) header += "#define RC_FAULT_DEPTH_BIAS\n";
  if (faults.shift_x) header += "#define RC_FAULT_SHIFT_X\n";
  if (faults.texel_offset) header += "#define RC_FAULT_TEXEL_OFFSET\n";
  std::string fragment_header = header;
  // The extension line must come before any other statement than #version and #define.
  if (faults.lod_weight)
    fragment_header +=
        "#extension GL_ARB_texture_query_lod : require\n#define RC_FAULT_LOD_WEIGHT\n";
  if (faults.compile_error) fragment_header += "#define RC_FAULT_COMPILE_ERROR\n";
  if (shadows) fragment_header += "#define RC_SHADOW_LOOKUP\n";
  if (shadows && faults.shadow_shift) fragment_header += "#define RC_FAULT_SHADOW_SHIFT\n";
  return {header + kLighting + kVertexMain, fragment_header + kLighting + kFragmentMain};
}

}  // namespace rc::gl
