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

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "fixtures/scene.h"
#include "fixtures/scene_geometry.h"
#include "reference/shadow.h"

namespace rc {

// One light's contribution at a shaded point (already multiplied by the material).
struct LightTerms {
  glm::dvec3 diffuse{0.0};
  glm::dvec3 specular{0.0};
};

// The factors one light's terms were computed from at one shaded point, recorded by the
// lighting code itself when it traces (ref::shadePrepared with a ShadingTerms): NaN
// where a factor does not apply. A light that does not contribute (zero normal, a point
// light at the shaded point) still gets the factors the formulas give.
struct LightFactors {
  double distance = std::numeric_limits<double>::quiet_NaN();  // point lights: r
  double attenuation = 1.0;                                    // att
  double n_dot_l = 0.0;
  double n_dot_h = std::numeric_limits<double>::quiet_NaN();  // Blinn-Phong
  double r_dot_v = std::numeric_limits<double>::quiet_NaN();  // Phong
  double specular_power = 0.0;                                // max(0, n.h or r.v)^shininess
  double shadow = 1.0;  // the shadow lookup's result multiplying diffuse and specular
  bool contributes = false;
};

// A point where the lighting model was evaluated for a fragment: the centroid (flat), each
// vertex (Gouraud, weight = the fragment's barycentric) or the fragment itself (Phong).
struct ShadedPoint {
  double weight = 1.0;
  glm::dvec3 position{0.0};  // world space
  glm::dvec3 normal{0.0};    // unit or zero
  glm::dvec3 ambient_diffuse{0.0};
  glm::dvec3 specular{0.0};
  std::vector<LightFactors> lights;  // one per scene light, in scene order
};

// Every term of one shaded colour, for `rastercheck explain` (see tracePixel()):
// color.rgb == (ambient + sum(lights[i].diffuse)) * texture + sum(lights[i].specular)
// (up to rounding when Gouraud interpolates the terms), color.a == opacity.
struct ShadingTerms {
  glm::dvec3 ambient{0.0};
  std::vector<LightTerms> lights;  // one per scene light, in scene order
  glm::dvec3 texture{1.0};         // texel rgb multiplying ambient and diffuse; 1 if untextured
  glm::dvec2 uv{0.0};              // the interpolated texture coordinate (textured only)
  // Level-of-detail sampling (textured, fixtures/scene.h lodSampling()): what chose the
  // level(s) (docs/reference.md "Textures: level of detail").
  struct Lod {
    bool used = false;
    glm::dvec2 d_dx{0.0};  // (du/dx, dv/dx), level-0 texels per px
    glm::dvec2 d_dy{0.0};
    double rho = 0.0;
    double lambda = 0.0;
    bool magnified = false;
    int level0 = 0;
    int level1 = 0;
    double weight = 0.0;     // of level1
    double lambda_lo = 0.0;  // the interval a conforming driver may use (tolerances.md 9)
    double lambda_hi = 0.0;
  } lod;
  glm::dvec4 color{0.0};
  std::vector<ShadedPoint> points;  // where the lighting was evaluated, with its factors
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

// normalize(v), zero when v has no direction: the one normaliser of the project,
// rc::safeNormalize in fixtures/scene_geometry.h (its rule for zero, denormal, infinite
// and NaN lengths is documented there). Named here too because callers outside the
// reference spell it ref::safeNormalize.
using rc::safeNormalize;

// max(0, base)^shininess with x^0 = 1. Integral exponents up to 128 use repeated squaring
// (relative error below shininess * 2^-52 against the exact power, and several times
// faster than pow); others std::pow.
double specularPower(double base, double shininess);

// The same for a shininess whose kind is decided once (specularExponent()): exponent 0
// is x^0 = 1, > 0 the integral exponent for repeated squaring, < 0 std::pow(base,
// shininess). Bit-identical to specularPower(base, shininess).
int specularExponent(double shininess);
inline double specularPower(double base, double shininess, int exponent) {
  if (exponent == 0) return 1.0;  // max(0, x)^0 = 1, including pow(0, 0)
  if (!(base > 0.0)) return 0.0;
  if (exponent < 0) return std::pow(base, shininess);
  auto e = static_cast<unsigned>(exponent);
  if ((e & (e - 1)) == 0) {  // 2^k: the loop below multiplies 1 by base^(2^k), exactly it
    double result = base;
    for (e >>= 1u; e != 0; e >>= 1u) result *= result;
    return result;
  }
  double result = 1.0;
  double square = base;
  while (e != 0) {
    if (e & 1u) result *= square;
    square *= square;
    e >>= 1u;
  }
  return result;
}

// The lighting model with everything that does not depend on the shaded point computed
// once per material (shadePoint() is this, prepared per call). Hoisting changes no
// result: each hoisted value is the very expression shadePoint() would evaluate per point
// (radiance = color * intensity is the first product of color * intensity * att, and
// multiplying by att = 1 is exact, so kd * radiance is kd * L for unattenuated lights).
struct PreparedLight {
  bool directional = false;
  bool attenuated = false;      // a point light under inverse or inverse_square
  glm::dvec3 position{0.0};     // point lights
  glm::dvec3 l{0.0};            // directional: -safeNormalize(direction), towards the light
  glm::dvec3 radiance{0.0};     // color * intensity
  glm::dvec3 kd_radiance{0.0};  // material.diffuse * radiance (unattenuated lights)
  glm::dvec3 ks_radiance{0.0};  // material.specular * radiance (unattenuated lights)
  // The material's shadow lookup when it reads this light's map (bound), else null.
  const ShadowLookup* shadow = nullptr;
};

struct PreparedShading {
  glm::dvec3 eye{0.0};
  glm::dvec3 ambient{0.0};  // material.ambient * ambient_light
  glm::dvec3 kd{0.0};
  glm::dvec3 ks{0.0};
  double shininess = 0.0;
  int exponent = 0;  // specularExponent(shininess)
  bool blinn = true;
  Attenuation attenuation = Attenuation::None;
  std::vector<PreparedLight> lights;
  bool shadowed = false;  // some light has a shadow lookup
};
PreparedShading prepareShading(const Lighting& lighting, const Material& material);

// Lights world point p with unit (or zero) normal n (DESIGN.md "Shading"; the formulas
// are at the top of this file). When terms is non-null it also records every term, and
// the point with every light's factors as terms->points = {this point} (the trace hook of
// `explain`: the factors it prints are the very values computed here). Tracing changes no
// result: a light that contributes nothing is still evaluated for its factors, then
// skipped, as it is without tracing.
// `shadows` false: every light unshadowed (the terms a shadow lookup would scale).
[[gnu::always_inline]] inline LitColor shadePrepared(const PreparedShading& s, const glm::dvec3& p,
                                                     const glm::dvec3& n,
                                                     ShadingTerms* terms = nullptr,
                                                     bool shadows = true) {
  LitColor out;
  out.ambient_diffuse = s.ambient;
  ShadedPoint* point = nullptr;
  if (terms) {
    terms->ambient = s.ambient;
    terms->lights.assign(s.lights.size(), LightTerms{});
    terms->points.assign(1, ShadedPoint{1.0, p, n, s.ambient, glm::dvec3(0.0), {}});
    point = &terms->points.front();
    point->lights.assign(s.lights.size(), LightFactors{});
  }
  const bool zero_normal = n == glm::dvec3(0.0);  // no diffuse, no specular
  if (zero_normal && !point) return out;

  const glm::dvec3 v = safeNormalize(s.eye - p);
  for (std::size_t i = 0; i < s.lights.size(); ++i) {
    const PreparedLight& light = s.lights[i];
    glm::dvec3 l(0.0);
    double att = 1.0;
    bool contributes = !zero_normal;
    if (light.directional) {
      l = light.l;
    } else {
      const glm::dvec3 to_light = light.position - p;
      const double r = std::sqrt(glm::dot(to_light, to_light));
      if (point) point->lights[i].distance = r;
      if (!(r > 0.0)) {  // light at the shaded point: contributes nothing
        if (!point) continue;
        contributes = false;
      } else {
        const double inv_r = 1.0 / r;
        l = to_light * inv_r;
        if (s.attenuation == Attenuation::Inverse) att = inv_r;
        if (s.attenuation == Attenuation::InverseSquare) att = 1.0 / (r * r);
      }
    }
    const double n_dot_l = glm::dot(n, l);
    double base = 0.0;
    double specular_cosine = 0.0;  // n.h or r.v before max(0, .)
    if (s.blinn) {
      const glm::dvec3 h = safeNormalize(l + v);
      specular_cosine = glm::dot(n, h);
    } else {
      const glm::dvec3 r = 2.0 * n_dot_l * n - l;
      specular_cosine = glm::dot(r, v);
    }
    base = std::max(0.0, specular_cosine);
    const double power = specularPower(base, s.shininess, s.exponent);
    if (point) {
      LightFactors& f = point->lights[i];
      f.attenuation = att;
      f.n_dot_l = n_dot_l;
      (s.blinn ? f.n_dot_h : f.r_dot_v) = specular_cosine;
      f.specular_power = power;
      f.contributes = contributes;
      if (!contributes) continue;
    }
    glm::dvec3 diffuse;
    glm::dvec3 specular;
    if (light.attenuated) {
      const glm::dvec3 L = light.radiance * att;
      diffuse = s.kd * L * std::max(0.0, n_dot_l);
      specular = s.ks * L * power;
    } else {
      diffuse = light.kd_radiance * std::max(0.0, n_dot_l);
      specular = light.ks_radiance * power;
    }
    if (shadows && light.shadow != nullptr) {  // GL: the lookup scales the light's terms
      const double f = shadowFactor(*light.shadow, p);
      if (point) point->lights[i].shadow = f;
      diffuse *= f;
      specular *= f;
    }
    out.ambient_diffuse += diffuse;
    out.specular += specular;
    if (terms) terms->lights[i] = LightTerms{diffuse, specular};
  }
  if (point) {
    point->ambient_diffuse = out.ambient_diffuse;
    point->specular = out.specular;
  }
  return out;
}

// Lights world point p with unit (or zero) normal n. When terms is non-null it also
// records every term (ambient and per-light; texture and color are left to the caller).
LitColor shadePoint(const Lighting& lighting, const Material& material, const glm::dvec3& p,
                    const glm::dvec3& n, ShadingTerms* terms = nullptr);

// (ambient + diffuse) o texture + specular, alpha = opacity.
inline glm::dvec4 finalColor(const LitColor& lit, const glm::dvec3& texture_rgb, double opacity) {
  return glm::dvec4(lit.ambient_diffuse * texture_rgb + lit.specular, opacity);
}

}  // namespace rc::ref
