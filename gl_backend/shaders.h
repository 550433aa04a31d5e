// The GLSL 330 programs of the backend. The lighting functions are the GLSL twin of
// reference/shading.cpp (same terms, same names, same order of operations where it
// matters); tests check both against hand-computed values.
#pragma once

#include <string>

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

// Values of the u_shading / u_specular_model / u_attenuation uniforms.
enum ShadingUniform : int { kShadingFlat = 0, kShadingGouraud = 1, kShadingPhong = 2 };
enum SpecularUniform : int { kSpecularPhong = 0, kSpecularBlinnPhong = 1 };
enum AttenuationUniform : int { kAttNone = 0, kAttInverse = 1, kAttInverseSquare = 2 };

struct ProgramSource {
  std::string vertex;
  std::string fragment;
};

// The program for scenes with up to max_lights lights (array sizes are compile-time
// constants in GLSL 330).
ProgramSource programSource(int max_lights);

}  // namespace rc::gl
