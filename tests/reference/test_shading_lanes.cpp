// The four- and eight-lane shading of untextured Phong spans (reference/shading_lanes.h) against
// the scalar shadePrepared() it stands for: every lane must give the scalar result bit for bit, on
// random points and normals and on every branch (zero normal, light at the shaded point,
// directional and point lights, each attenuation, both specular models, shininess 0,
// integral, power of two and fractional), compiled for x86-64's baseline and for AVX2.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "reference/shading.h"
#include "reference/shading_lanes.h"

// Lane4 values never cross a call here (everything is inlined): -Wpsabi's ABI note does
// not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace rc {
namespace {

using namespace rc::ref;

// Eight points and normals: the Lane8 form shades all eight, the Lane4 form the first
// four and then the last four.
struct LaneInput {
  glm::dvec3 p[8];
  glm::dvec3 n[8];
};
struct LaneOutput {
  glm::dvec3 ad[8];
  glm::dvec3 sp[8];
};

double laneOf(Lane4 v, int k) { return v[k]; }
double laneOf(const Lane8& v, int k) { return v[k]; }

template <class V>
void unpack(const LitColorL<V>& lit, int first, LaneOutput& out) {
  for (int k = 0; k < kLaneCount<V>; ++k) {
    out.ad[first + k] = {laneOf(lit.ambient_diffuse.x, k), laneOf(lit.ambient_diffuse.y, k),
                         laneOf(lit.ambient_diffuse.z, k)};
    out.sp[first + k] = {laneOf(lit.specular.x, k), laneOf(lit.specular.y, k),
                         laneOf(lit.specular.z, k)};
  }
}

template <class V>
Vec3L<V> pack(const glm::dvec3* v) {
  Vec3L<V> r{};
  for (int k = 0; k < kLaneCount<V>; ++k) {
    setLane(r.x, k, v[k].x);
    setLane(r.y, k, v[k].y);
    setLane(r.z, k, v[k].z);
  }
  return r;
}

template <class V>
[[gnu::always_inline]] inline LaneOutput shadeLanes(const PreparedShading& s, const LaneInput& in) {
  LaneOutput out;
  for (int first = 0; first < 8; first += kLaneCount<V>)
    unpack<V>(
        shadePreparedLanes<V>(s, pack<V>(in.p + first), safeNormalizeLanes(pack<V>(in.n + first))),
        first, out);
  return out;
}

// The same inlined code compiled for the baseline and for AVX2 (as the renderer's
// target_clones function is), four and eight lanes at a time.
LaneOutput shadeBaseline4(const PreparedShading& s, const LaneInput& in) {
  return shadeLanes<Lane4>(s, in);
}
LaneOutput shadeBaseline8(const PreparedShading& s, const LaneInput& in) {
  return shadeLanes<Lane8>(s, in);
}
__attribute__((target("avx2"))) LaneOutput shadeAvx2_4(const PreparedShading& s,
                                                       const LaneInput& in) {
  return shadeLanes<Lane4>(s, in);
}
__attribute__((target("avx2"))) LaneOutput shadeAvx2_8(const PreparedShading& s,
                                                       const LaneInput& in) {
  return shadeLanes<Lane8>(s, in);
}

bool sameBits(const glm::dvec3& a, const glm::dvec3& b) {
  for (int c = 0; c < 3; ++c)
    if (std::bit_cast<std::uint64_t>(a[c]) != std::bit_cast<std::uint64_t>(b[c])) return false;
  return true;
}

// Checks every lane of both builds, four and eight lanes wide, against
// shadePrepared(s, p, safeNormalize(n)).
void expectLanesEqualScalar(const PreparedShading& s, const LaneInput& in, const char* what) {
  const bool avx2 = __builtin_cpu_supports("avx2");
  const LaneOutput outs[4] = {shadeBaseline4(s, in), shadeBaseline8(s, in),
                              avx2 ? shadeAvx2_4(s, in) : shadeBaseline4(s, in),
                              avx2 ? shadeAvx2_8(s, in) : shadeBaseline8(s, in)};
  const char* builds[4] = {"baseline, 4 lanes", "baseline, 8 lanes", "AVX2, 4 lanes",
                           "AVX2, 8 lanes"};
  for (int k = 0; k < 8; ++k) {
    const LitColor scalar = shadePrepared(s, in.p[k], safeNormalize(in.n[k]));
    for (int b = 0; b < 4; ++b)
      EXPECT_TRUE(sameBits(outs[b].ad[k], scalar.ambient_diffuse) &&
                  sameBits(outs[b].sp[k], scalar.specular))
          << what << " lane " << k << ": " << builds[b] << " differ from the scalar shading";
  }
}

TEST(ShadingLanes, EveryLaneIsTheScalarShadingBitForBit) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> coord(-3.0, 3.0);
  auto vec = [&] { return glm::dvec3(coord(rng), coord(rng), coord(rng)); };
  const std::vector<Light> lights = {
      Light{LightType::Point, {1.0, 2.0, 3.0}, {}, {1.0, 0.9, 0.8}, 1.5},
      Light{LightType::Directional, {}, {0.3, -1.0, -0.2}, {0.5, 0.6, 0.7}, 0.8},
      Light{LightType::Point, {-2.0, 0.5, 1.0}, {}, {0.2, 0.4, 1.0}, 2.0}};
  int cases = 0;
  for (const double shininess : {0.0, 1.0, 5.0, 32.0, 100.0, 128.0, 7.5, 200.0}) {
    for (const SpecularModel model : {SpecularModel::BlinnPhong, SpecularModel::Phong}) {
      for (const Attenuation att :
           {Attenuation::None, Attenuation::Inverse, Attenuation::InverseSquare}) {
        Material m;
        m.ambient = {0.2, 0.3, 0.4};
        m.diffuse = {0.6, 0.5, 0.4};
        m.specular = {0.5, 0.7, 0.9};
        m.shininess = shininess;
        Lighting lighting;
        lighting.eye = {0.5, 1.0, 6.0};
        lighting.ambient_light = glm::dvec3(0.1);
        lighting.lights = &lights;
        lighting.specular_model = model;
        lighting.attenuation = att;
        const PreparedShading s = prepareShading(lighting, m);
        for (int round = 0; round < 40; ++round) {
          LaneInput in;
          for (int k = 0; k < 8; ++k) {
            in.p[k] = vec();
            in.n[k] = vec();
          }
          // Branches: a zero normal, a point at the first light, a point at the eye.
          if (round % 4 == 1) in.n[round % 3] = glm::dvec3(0.0);
          if (round % 4 == 2) in.n[4 + round % 3] = glm::dvec3(0.0);
          if (round % 5 == 2) in.p[3] = lights[0].position;
          if (round % 5 == 3) in.p[6] = lights[2].position;
          if (round % 7 == 3) in.p[1] = lighting.eye;
          if (round % 7 == 4) in.p[7] = lighting.eye;
          expectLanesEqualScalar(s, in, "random");
          ++cases;
        }
      }
    }
  }
  EXPECT_EQ(cases, 8 * 2 * 3 * 40);
}

// An injected fault must show: the scalar shading of a point moved by 1e-9 (a few thousand
// ulps) differs in its bits from the lane's (the comparison above is not vacuous).
TEST(ShadingLanes, ComparisonSeesASmallMove) {
  const std::vector<Light> lights = {
      Light{LightType::Point, {1.0, 2.0, 3.0}, {}, {1.0, 1.0, 1.0}, 1.0}};
  Material m;
  m.diffuse = glm::dvec3(0.5);
  m.specular = glm::dvec3(0.5);
  m.shininess = 32.0;
  Lighting lighting;
  lighting.eye = {0.0, 0.0, 5.0};
  lighting.lights = &lights;
  const PreparedShading s = prepareShading(lighting, m);
  LaneInput in;
  for (int k = 0; k < 8; ++k) {
    in.p[k] = {0.1 * k, 0.2, 0.3};
    in.n[k] = {0.1, 0.2, 1.0};
  }
  for (const LaneOutput& base : {shadeBaseline4(s, in), shadeBaseline8(s, in)}) {
    for (const int k : {2, 6}) {
      const glm::dvec3 moved_p = {in.p[k].x + 1e-9, in.p[k].y, in.p[k].z};
      const LitColor scalar = shadePrepared(s, moved_p, safeNormalize(in.n[k]));
      EXPECT_FALSE(sameBits(base.ad[k], scalar.ambient_diffuse) &&
                   sameBits(base.sp[k], scalar.specular));
      // And unmoved, the same bits (the lane is the one compared).
      const LitColor same = shadePrepared(s, in.p[k], safeNormalize(in.n[k]));
      EXPECT_TRUE(sameBits(base.ad[k], same.ambient_diffuse) &&
                  sameBits(base.sp[k], same.specular));
    }
  }
}

}  // namespace
}  // namespace rc
