// Shading: the lighting formulas of DESIGN.md "Shading", the single C++ source of truth
// (gl_backend/shaders.cpp holds the GLSL twin, with the same function names). All vectors
// are world-space and unit length:
//   ambient  = ka o ambient_light
//   L        = light.color * light.intensity * att,  att = 1, 1/r or 1/r^2 (point lights;
//              directional lights always 1); l towards the light, v towards camera.eye
//   diffuse  = kd o L * max(0, n.l)
//   specular = ks o L * max(0, n.h)^s, h = normalize(l + v)        (Blinn-Phong)
//            = ks o L * max(0, r.v)^s, r = 2(n.l)n - l             (Phong)
//   colour   = (ambient + sum diffuse) o texture + sum specular, alpha = opacity
// No clamping (the framebuffer format does that). Conventions where the notes are
// silent: max(0, x)^0 = 1 (so pow(0, 0) := 1); a zero normal gives no diffuse and no
// specular; a point light exactly at the shaded point contributes nothing (1/r and l
// are undefined there). It does not interpolate or sample textures.
#pragma once

#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "fixtures/scene.h"

namespace rc {

// One light's contribution at a shaded point (already multiplied by the material).
struct LightTerms {
  glm::dvec3 diffuse{0.0};
  glm::dvec3 specular{0.0};
};

// Every term of one shaded colour, for `rastercheck explain` (see tracePixel()):
// color.rgb == (ambient + sum(lights[i].diffuse)) * texture + sum(lights[i].specular)
// (up to rounding when Gouraud interpolates the terms), color.a == opacity.
struct ShadingTerms {
  glm::dvec3 ambient{0.0};
  std::vector<LightTerms> lights;  // one per scene light, in scene order
  glm::dvec3 texture{1.0};         // texel rgb multiplying ambient and diffuse; 1 if untextured
  glm::dvec4 color{0.0};
};

}  // namespace rc

namespace rc::ref {

// The scene-wide inputs of the lighting model.
struct Lighting {
  glm::dvec3 eye{0.0};
  glm::dvec3 ambient_light{0.0};
  const std::vector<Light>* lights = nullptr;
  SpecularModel specular_model = SpecularModel::BlinnPhong;
  Attenuation attenuation = Attenuation::None;
};
Lighting sceneLighting(const Scene& scene);

// A lit colour split into the part a texture multiplies and the part it does not.
struct LitColor {
  glm::dvec3 ambient_diffuse{0.0};  // ambient + sum diffuse
  glm::dvec3 specular{0.0};         // sum specular
};

// normalize(v) with zero (or a non-finite length) staying zero. One division, not three
// (within an ulp of v / |v|).
inline glm::dvec3 safeNormalize(const glm::dvec3& v) {
  const double len = std::sqrt(glm::dot(v, v));
  if (!(len > 0.0) || !std::isfinite(len)) return glm::dvec3(0.0);
  return v * (1.0 / len);
}

// max(0, base)^shininess with x^0 = 1. Integral exponents up to 128 use repeated squaring
// (relative error below shininess * 2^-52 against the exact power, and several times
// faster than pow); others std::pow.
double specularPower(double base, double shininess);

// Lights world point p with unit (or zero) normal n. When terms is non-null it also
// records every term (ambient and per-light; texture and color are left to the caller).
LitColor shadePoint(const Lighting& lighting, const Material& material, const glm::dvec3& p,
                    const glm::dvec3& n, ShadingTerms* terms = nullptr);

// (ambient + diffuse) o texture + specular, alpha = opacity.
inline glm::dvec4 finalColor(const LitColor& lit, const glm::dvec3& texture_rgb, double opacity) {
  return glm::dvec4(lit.ambient_diffuse * texture_rgb + lit.specular, opacity);
}

}  // namespace rc::ref
