// Shading: see shading.h (the formulas are written out there, in the notes' order).
#include "reference/shading.h"

#include <cmath>

namespace rc::ref {

Lighting sceneLighting(const Scene& scene) {
  Lighting l;
  l.eye = scene.camera.eye;
  l.ambient_light = scene.ambient_light;
  l.lights = &scene.lights;
  l.specular_model = scene.state.specular_model;
  l.attenuation = scene.state.attenuation;
  return l;
}

double specularPower(double base, double shininess) {
  if (shininess == 0.0) return 1.0;  // max(0, x)^0 = 1, including pow(0, 0)
  if (!(base > 0.0)) return 0.0;
  // Integral test by conversion (std::floor is a libm call without SSE4.1).
  if (shininess > 0.0 && shininess <= 128.0 &&
      static_cast<double>(static_cast<int>(shininess)) == shininess) {
    auto e = static_cast<unsigned>(shininess);
    double result = 1.0;
    double square = base;
    while (e != 0) {
      if (e & 1u) result *= square;
      square *= square;
      e >>= 1u;
    }
    return result;
  }
  return std::pow(base, shininess);
}

LitColor shadePoint(const Lighting& lighting, const Material& material, const glm::dvec3& p,
                    const glm::dvec3& n, ShadingTerms* terms) {
  LitColor out;
  const glm::dvec3 ambient = material.ambient * lighting.ambient_light;
  out.ambient_diffuse = ambient;
  const std::size_t light_count = lighting.lights ? lighting.lights->size() : 0;
  if (terms) {
    terms->ambient = ambient;
    terms->lights.assign(light_count, LightTerms{});
  }
  if (n == glm::dvec3(0.0)) return out;  // zero normal: no diffuse, no specular

  const glm::dvec3 v = safeNormalize(lighting.eye - p);
  for (std::size_t i = 0; i < light_count; ++i) {
    const Light& light = (*lighting.lights)[i];
    glm::dvec3 l;
    double att = 1.0;
    if (light.type == LightType::Directional) {
      l = -safeNormalize(light.direction);
    } else {
      const glm::dvec3 to_light = light.position - p;
      const double r = std::sqrt(glm::dot(to_light, to_light));
      if (!(r > 0.0)) continue;  // light at the shaded point: contributes nothing
      const double inv_r = 1.0 / r;
      l = to_light * inv_r;
      if (lighting.attenuation == Attenuation::Inverse) att = inv_r;
      if (lighting.attenuation == Attenuation::InverseSquare) att = 1.0 / (r * r);
    }
    const glm::dvec3 L = light.color * light.intensity * att;
    const double n_dot_l = glm::dot(n, l);
    const glm::dvec3 diffuse = material.diffuse * L * std::max(0.0, n_dot_l);
    double base = 0.0;
    if (lighting.specular_model == SpecularModel::BlinnPhong) {
      const glm::dvec3 h = safeNormalize(l + v);
      base = std::max(0.0, glm::dot(n, h));
    } else {
      const glm::dvec3 r = 2.0 * n_dot_l * n - l;
      base = std::max(0.0, glm::dot(r, v));
    }
    const glm::dvec3 specular = material.specular * L * specularPower(base, material.shininess);
    out.ambient_diffuse += diffuse;
    out.specular += specular;
    if (terms) terms->lights[i] = LightTerms{diffuse, specular};
  }
  return out;
}

}  // namespace rc::ref
