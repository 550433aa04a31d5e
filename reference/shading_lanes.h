// Four or eight fragments at a time: shadePrepared() (shading.h) evaluated in the lanes of
// vectors (lanes.h; V is Lane4 or Lane8), so that the span loop of untextured Phong shares its
// instructions, square roots and divisions between fragments. Every lane performs exactly the
// scalar code's IEEE operations on the same operands in the same order, and every branch of the
// scalar code becomes a per-lane select of the value that branch gives, so each lane's result has
// the bits of shadePrepared() on that lane's input (test ShadingLanes.*). It does not trace terms.
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

template <class V>
struct Vec3L {
  V x;
  V y;
  V z;
};
using Vec3x4 = Vec3L<Lane4>;
template <class V>
[[gnu::always_inline]] inline Vec3L<V> splatVec(const glm::dvec3& v) {
  return {splatAs<V>(v.x), splatAs<V>(v.y), splatAs<V>(v.z)};
}
template <class V>
[[gnu::always_inline]] inline Vec3L<V> operator+(const Vec3L<V>& a, const Vec3L<V>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
[[gnu::always_inline]] inline Vec3L<V> operator-(const Vec3L<V>& a, const Vec3L<V>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class V>
[[gnu::always_inline]] inline Vec3L<V> operator*(const Vec3L<V>& a, const Vec3L<V>& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class V>
[[gnu::always_inline]] inline Vec3L<V> operator*(const Vec3L<V>& a, V s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class V>
[[gnu::always_inline]] inline Vec3L<V> selectLanes(MaskOf<V> m, const Vec3L<V>& a,
                                                   const Vec3L<V>& b) {
  return {selectLanes(m, a.x, b.x), selectLanes(m, a.y, b.y), selectLanes(m, a.z, b.z)};
}
// glm::dot on dvec3: (x * x' + y * y') + z * z'.
template <class V>
[[gnu::always_inline]] inline V dotLanes(const Vec3L<V>& a, const Vec3L<V>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
// b.x * v0 + b.y * v1 + b.z * v2 as glm evaluates it: (b.x v0 + b.y v1) + b.z v2.
template <class V>
[[gnu::always_inline]] inline Vec3L<V> combineLanes(V bx, V by, V bz, const glm::dvec3& v0,
                                                    const glm::dvec3& v1, const glm::dvec3& v2) {
  return {(bx * splatAs<V>(v0.x) + by * splatAs<V>(v1.x)) + bz * splatAs<V>(v2.x),
          (bx * splatAs<V>(v0.y) + by * splatAs<V>(v1.y)) + bz * splatAs<V>(v2.y),
          (bx * splatAs<V>(v0.z) + by * splatAs<V>(v1.z)) + bz * splatAs<V>(v2.z)};
}

// safeNormalize() per lane.
template <class V>
[[gnu::always_inline]] inline Vec3L<V> safeNormalizeLanes(const Vec3L<V>& v) {
  const V len = sqrtLanes(dotLanes(v, v));
  // len >= 0 or NaN: finite and > 0 exactly when 0 < len < inf.
  const MaskOf<V> ok =
      (len > splatAs<V>(0.0)) & (len < splatAs<V>(std::numeric_limits<double>::infinity()));
  const V inv = splatAs<V>(1.0) / len;
  return selectLanes(ok, v * inv, splatVec<V>(glm::dvec3(0.0)));
}

// specularPower(base, shininess, exponent) per lane (the exponent is the material's).
template <class V>
[[gnu::always_inline]] inline V specularPowerLanes(V base, double shininess, int exponent) {
  if (exponent == 0) return splatAs<V>(1.0);
  V result;
  if (exponent < 0) {
    for (int k = 0; k < kLaneCount<V>; ++k) setLane(result, k, std::pow(base[k], shininess));
  } else {
    auto e = static_cast<unsigned>(exponent);
    if ((e & (e - 1)) == 0) {
      result = base;
      for (e >>= 1u; e != 0; e >>= 1u) result *= result;
    } else {
      result = splatAs<V>(1.0);
      V square = base;
      while (e != 0) {
        if (e & 1u) result *= square;
        square *= square;
        e >>= 1u;
      }
    }
  }
  return selectLanes(base > splatAs<V>(0.0), result, splatAs<V>(0.0));
}

// shadePrepared(s, p, n) for the lanes' points and normals: the lit colour's ambient +
// diffuse and specular, per lane.
template <class V>
struct LitColorL {
  Vec3L<V> ambient_diffuse;
  Vec3L<V> specular;
};
using LitColor4 = LitColorL<Lane4>;
template <class V>
[[gnu::always_inline]] inline LitColorL<V> shadePreparedLanes(const PreparedShading& s,
                                                              const Vec3L<V>& p,
                                                              const Vec3L<V>& n) {
  // The sums in plain locals, not in a LitColorL built up front: GCC copied that aggregate
  // through the stack in 8-byte pieces on every call.
  Vec3L<V> ambient_diffuse = splatVec<V>(s.ambient);
  Vec3L<V> specular_sum = splatVec<V>(glm::dvec3(0.0));
  const V zero = splatAs<V>(0.0);
  const V one = splatAs<V>(1.0);
  // n == 0 (every component compares equal to zero): ambient only.
  const MaskOf<V> zero_normal = (n.x == zero) & (n.y == zero) & (n.z == zero);
  const Vec3L<V> v = safeNormalizeLanes(splatVec<V>(s.eye) - p);
  for (const PreparedLight& light : s.lights) {
    Vec3L<V> l;
    V att = one;
    MaskOf<V> lit = ~zero_normal;
    if (light.directional) {
      l = splatVec<V>(light.l);
    } else {
      const Vec3L<V> to_light = splatVec<V>(light.position) - p;
      const V r = sqrtLanes(dotLanes(to_light, to_light));
      lit &= r > zero;  // light at the shaded point: contributes nothing
      const V inv_r = one / r;
      l = to_light * inv_r;
      if (s.attenuation == Attenuation::Inverse) att = inv_r;
      if (s.attenuation == Attenuation::InverseSquare) att = one / (r * r);
    }
    const V n_dot_l = dotLanes(n, l);
    V base;
    if (s.blinn) {
      const Vec3L<V> h = safeNormalizeLanes(l + v);
      base = maxZeroLanes(dotLanes(n, h));
    } else {
      const Vec3L<V> r = n * (splatAs<V>(2.0) * n_dot_l) - l;
      base = maxZeroLanes(dotLanes(r, v));
    }
    const V power = specularPowerLanes(base, s.shininess, s.exponent);
    Vec3L<V> diffuse;
    Vec3L<V> specular;
    if (light.attenuated) {
      const Vec3L<V> L = splatVec<V>(light.radiance) * att;
      diffuse = (splatVec<V>(s.kd) * L) * maxZeroLanes(n_dot_l);
      specular = (splatVec<V>(s.ks) * L) * power;
    } else {
      diffuse = splatVec<V>(light.kd_radiance) * maxZeroLanes(n_dot_l);
      specular = splatVec<V>(light.ks_radiance) * power;
    }
    ambient_diffuse = selectLanes(lit, ambient_diffuse + diffuse, ambient_diffuse);
    specular_sum = selectLanes(lit, specular_sum + specular, specular_sum);
  }
  return LitColorL<V>{ambient_diffuse, specular_sum};
}

#pragma GCC diagnostic pop

}  // namespace rc::ref
