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

int specularExponent(double shininess) {
  if (shininess == 0.0) return 0;
  // Integral test by conversion (std::floor is a libm call without SSE4.1).
  if (shininess > 0.0 && shininess <= 128.0 &&
      static_cast<double>(static_cast<int>(shininess)) == shininess)
    return static_cast<int>(shininess);
  return -1;
}

double specularPower(double base, double shininess) {
  return specularPower(base, shininess, specularExponent(shininess));
}

PreparedShading prepareShading(const Lighting& lighting, const Material& material) {
  PreparedShading s;
  s.eye = lighting.eye;
  s.ambient = material.ambient * lighting.ambient_light;
  s.kd = material.diffuse;
  s.ks = material.specular;
  s.shininess = material.shininess;
  s.exponent = specularExponent(material.shininess);
  s.blinn = lighting.specular_model == SpecularModel::BlinnPhong;
  s.attenuation = lighting.attenuation;
  if (lighting.lights) {
    for (const Light& light : *lighting.lights) {
      PreparedLight p;
      p.directional = light.type == LightType::Directional;
      p.attenuated = !p.directional && lighting.attenuation != Attenuation::None;
      p.position = light.position;
      if (p.directional) p.l = -safeNormalize(light.direction);
      p.radiance = light.color * light.intensity;
      p.kd_radiance = material.diffuse * p.radiance;
      p.ks_radiance = material.specular * p.radiance;
      if (material.shadow && material.shadow->data && !light.shadow_map.empty() &&
          light.shadow_map == material.shadow->map) {
        p.shadow = &*material.shadow;
        s.shadowed = true;
      }
      s.lights.push_back(p);
    }
  }
  return s;
}

LitColor shadePoint(const Lighting& lighting, const Material& material, const glm::dvec3& p,
                    const glm::dvec3& n, ShadingTerms* terms) {
  return shadePrepared(prepareShading(lighting, material), p, n, terms);
}

}  // namespace rc::ref
