// The GLSL 330 programs of the backend. The lighting functions are the GLSL twin of
// reference/shading.cpp (same terms, same names, same order of operations where it
// matters); tests check both against hand-computed values.
#pragma once

#include <string>
#include <vector>

namespace rc::gl {

// Attribute locations of the one interleaved vertex buffer (see vertex_data.h).
enum AttributeLocation : unsigned {
  kAttribWorldPosition = 0,
  kAttribWorldNormal = 1,
  kAttribUv = 2,
  kAttribPrimitiveId = 3,  // flat uint: softpipe draws nothing if gl_PrimitiveID is read
  kAttribFaceCentroid = 4,
  kAttribFaceNormal = 5,
};

// The u_shading, u_specular_model, u_attenuation and u_light_type uniforms carry the C++
// enum's own value, and the GLSL compares them with #defines generated from those enums
// (glslEnumDefines: RC_SHADING_FLAT, RC_SPECULAR_BLINN_PHONG, RC_ATTENUATION_INVERSE,
// RC_LIGHT_DIRECTIONAL, ...), so the two languages cannot disagree about a value.
template <class E>
constexpr int uniformValue(E value) {
  return static_cast<int>(value);
}

// One generated #define: its name and the C++ value it stands for.
struct GlslEnumDefine {
  std::string name;  // RC_<ENUM>_<VALUE NAME>
  int value;
};
// Every enum value the shaders test, in the order of the enums' declarations.
const std::vector<GlslEnumDefine>& glslEnumDefines();

struct ProgramSource {
  std::string vertex;
  std::string fragment;
};

// Test-only faults compiled into the program (gl_testing.h). With none set, the program
// text is exactly the production one; each set fault adds one #define.
struct ShaderFaults {
  bool depth_bias = false;     // gl_FragDepth = gl_FragCoord.z + u_fault_depth_bias
  bool shift_x = false;        // gl_Position.x += u_fault_shift_ndc * gl_Position.w
  bool compile_error = false;  // the fragment shader calls a function that does not exist
  bool texel_offset = false;   // texture() samples at v_uv + u_fault_texel_offset texels in s
  bool lod_weight = false;     // two mip levels blended with the weight inverted (1 - f)
  bool shadow_shift = false;   // shadow lookups u_fault_shadow_shift map texels to the right
};

// The program for scenes with up to max_lights lights (array sizes are compile-time
// constants in GLSL 330); `shadows`: with the shadow lookup (a fragment-stage sampler2DShadow
// scaling the shadowed lights' terms), for scenes whose materials have one.
ProgramSource programSource(int max_lights, const ShaderFaults& faults = {}, bool shadows = false);

}  // namespace rc::gl
