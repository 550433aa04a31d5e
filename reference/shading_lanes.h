// Four fragments at a time: shadePrepared() (shading.h) evaluated in the lanes of vectors
// (lanes.h), so that the span loop of untextured Phong shares its instructions, square
// roots and divisions between fragments. Every lane performs exactly the scalar code's IEEE
// operations on the same operands in the same order, and every branch of the scalar code
// becomes a per-lane select of the value that branch gives, so each lane's result has the
// bits of shadePrepared() on that lane's input (test ShadingLanes.*). It does not trace
// terms.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

#include "reference/lanes.h"
#include "reference/shading.h"

namespace rc::ref {

// Lane4 values never cross a call (everything is always_inline), so the ABI note of
// -Wpsabi about passing 32-byte vectors without AVX does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

struct Vec3x4 {
  Lane4 x;
  Lane4 y;
  Lane4 z;
};
[[gnu::always_inline]] inline Vec3x4 splat4(const glm::dvec3& v) {
  return {splat4(v.x), splat4(v.y), splat4(v.z)};
}
[[gnu::always_inline]] inline Vec3x4 operator+(const Vec3x4& a, const Vec3x4& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
[[gnu::always_inline]] inline Vec3x4 operator-(const Vec3x4& a, const Vec3x4& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
[[gnu::always_inline]] inline Vec3x4 operator*(const Vec3x4& a, const Vec3x4& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
[[gnu::always_inline]] inline Vec3x4 operator*(const Vec3x4& a, Lane4 s) {
  return {a.x * s, a.y * s, a.z * s};
}
[[gnu::always_inline]] inline Vec3x4 select4(Mask4 m, const Vec3x4& a, const Vec3x4& b) {
  return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
}
// glm::dot on dvec3: (x * x' + y * y') + z * z'.
[[gnu::always_inline]] inline Lane4 dot4(const Vec3x4& a, const Vec3x4& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
// b.x * v0 + b.y * v1 + b.z * v2 as glm evaluates it: (b.x v0 + b.y v1) + b.z v2.
[[gnu::always_inline]] inline Vec3x4 combine4(Lane4 bx, Lane4 by, Lane4 bz, const glm::dvec3& v0,
                                              const glm::dvec3& v1, const glm::dvec3& v2) {
  return {(bx * splat4(v0.x) + by * splat4(v1.x)) + bz * splat4(v2.x),
          (bx * splat4(v0.y) + by * splat4(v1.y)) + bz * splat4(v2.y),
          (bx * splat4(v0.z) + by * splat4(v1.z)) + bz * splat4(v2.z)};
}

// safeNormalize() per lane.
[[gnu::always_inline]] inline Vec3x4 safeNormalize4(const Vec3x4& v) {
  const Lane4 len = sqrt4(dot4(v, v));
  // len >= 0 or NaN: finite and > 0 exactly when 0 < len < inf.
  const Mask4 ok = (len > splat4(0.0)) & (len < splat4(std::numeric_limits<double>::infinity()));
  const Lane4 inv = splat4(1.0) / len;
  const Vec3x4 zero = splat4(glm::dvec3(0.0));
  return select4(ok, v * inv, zero);
}

// specularPower(base, shininess, exponent) per lane (the exponent is the material's).
[[gnu::always_inline]] inline Lane4 specularPower4(Lane4 base, double shininess, int exponent) {
  if (exponent == 0) return splat4(1.0);
  Lane4 result;
  if (exponent < 0) {
    result = Lane4{std::pow(base[0], shininess), std::pow(base[1], shininess),
                   std::pow(base[2], shininess), std::pow(base[3], shininess)};
  } else {
    auto e = static_cast<unsigned>(exponent);
    if ((e & (e - 1)) == 0) {
      result = base;
      for (e >>= 1u; e != 0; e >>= 1u) result *= result;
    } else {
      result = splat4(1.0);
      Lane4 square = base;
      while (e != 0) {
        if (e & 1u) result *= square;
        square *= square;
        e >>= 1u;
      }
    }
  }
  return base > splat4(0.0) ? result : splat4(0.0);
}

// shadePrepared(s, p, n) for two points and normals: the lit colour's ambient + diffuse
// and specular, per lane.
struct LitColor4 {
  Vec3x4 ambient_diffuse;
  Vec3x4 specular;
};
[[gnu::always_inline]] inline LitColor4 shadePrepared4(const PreparedShading& s, const Vec3x4& p,
                                                       const Vec3x4& n) {
  // The sums in plain locals, not in a LitColor4 built up front: GCC copied that aggregate
  // through the stack in 8-byte pieces on every call.
  Vec3x4 ambient_diffuse = splat4(s.ambient);
  Vec3x4 specular_sum = {splat4(0.0), splat4(0.0), splat4(0.0)};
  // n == 0 (every component compares equal to zero): ambient only.
  const Mask4 zero_normal = (n.x == splat4(0.0)) & (n.y == splat4(0.0)) & (n.z == splat4(0.0));
  const Vec3x4 v = safeNormalize4(splat4(s.eye) - p);
  for (const PreparedLight& light : s.lights) {
    Vec3x4 l;
    Lane4 att = splat4(1.0);
    Mask4 lit = ~zero_normal;
    if (light.directional) {
      l = splat4(light.l);
    } else {
      const Vec3x4 to_light = splat4(light.position) - p;
      const Lane4 r = sqrt4(dot4(to_light, to_light));
      lit &= r > splat4(0.0);  // light at the shaded point: contributes nothing
      const Lane4 inv_r = splat4(1.0) / r;
      l = to_light * inv_r;
      if (s.attenuation == Attenuation::Inverse) att = inv_r;
      if (s.attenuation == Attenuation::InverseSquare) att = splat4(1.0) / (r * r);
    }
    const Lane4 n_dot_l = dot4(n, l);
    Lane4 base;
    if (s.blinn) {
      const Vec3x4 h = safeNormalize4(l + v);
      base = maxZero4(dot4(n, h));
    } else {
      const Vec3x4 r = n * (splat4(2.0) * n_dot_l) - l;
      base = maxZero4(dot4(r, v));
    }
    const Lane4 power = specularPower4(base, s.shininess, s.exponent);
    Vec3x4 diffuse;
    Vec3x4 specular;
    if (light.attenuated) {
      const Vec3x4 L = splat4(light.radiance) * att;
      diffuse = (splat4(s.kd) * L) * maxZero4(n_dot_l);
      specular = (splat4(s.ks) * L) * power;
    } else {
      diffuse = splat4(light.kd_radiance) * maxZero4(n_dot_l);
      specular = splat4(light.ks_radiance) * power;
    }
    ambient_diffuse = select4(lit, ambient_diffuse + diffuse, ambient_diffuse);
    specular_sum = select4(lit, specular_sum + specular, specular_sum);
  }
  return LitColor4{ambient_diffuse, specular_sum};
}

#pragma GCC diagnostic pop

}  // namespace rc::ref
