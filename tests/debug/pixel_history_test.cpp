// The debug library's pixel history (debug/pixel_history.h) called directly, on scenes
// built in code: the per-light factors explain prints are those of the reference's own
// lighting code and equal their closed forms; the history of a covered pixel; a backend's
// class and per-pixel verdict on frames altered by hand.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/pair_tolerances.h"
#include "debug/pixel_history.h"
#include "fixtures/errors.h"
#include "reference/reference_renderer.h"
#include "tests/debug/debug_lib_scenes.h"

namespace rc {
namespace {

using debugtest::addBigQuad;
using debugtest::addQuad;
using debugtest::directionalLight;
using debugtest::litWindow;
using debugtest::pointLight;
using Json = nlohmann::ordered_json;

Json historyAt(const Scene& scene, int x, int y, const ReferenceOptions& options = {}) {
  PixelQuery q;
  q.fixture_file = "in-memory";
  q.reference_spec = "ref";
  q.options = options;
  q.x = x;
  q.y = y;
  return pixelHistory(scene, q, renderReference(scene, options));
}

// One quad at z = 0 lit at the origin by a point light at (0, 3, 4) (r = 5,
// l = (0, .6, .8)) and a directional light shining along -z (l = (0, 0, 1)); v = (0, 0, 1).
Scene factorScene(SpecularModel model, Attenuation attenuation, Shading shading) {
  Scene s = litWindow();
  s.state.specular_model = model;
  s.state.attenuation = attenuation;
  s.state.shading = shading;
  addBigQuad(s, 0.0f, "quad");
  s.lights = {pointLight({0.0, 3.0, 4.0}), directionalLight({0.0, 0.0, -1.0})};
  return s;
}

const Json& factorsOf(const Json& doc, int light) {
  return doc["fragments"][0]["shading"]["lights"][light]["factors"][0];
}

TEST(PixelHistory, BlinnPhongFactorsAreTheClosedForms) {
  const Json doc =
      historyAt(factorScene(SpecularModel::BlinnPhong, Attenuation::Inverse, Shading::Phong), 1, 1);
  ASSERT_EQ(doc["fragments"].size(), 1u) << doc.dump(2);
  const Json& point = factorsOf(doc, 0);
  EXPECT_NEAR(point["distance"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(point["attenuation"].get<double>(), 0.2, 1e-9);  // 1 / r
  EXPECT_NEAR(point["n_dot_l"].get<double>(), 0.8, 1e-9);
  // h = normalize(l + v) = (0, .6, 1.8) / sqrt(3.6)
  EXPECT_NEAR(point["n_dot_h"].get<double>(), 1.8 / std::sqrt(3.6), 1e-9);
  EXPECT_TRUE(point["r_dot_v"].is_null());
  EXPECT_NEAR(point["specular_power"].get<double>(), 1.8 / std::sqrt(3.6), 1e-9);  // s = 1
  EXPECT_TRUE(point["contributes"].get<bool>());
  const Json& sun = factorsOf(doc, 1);
  EXPECT_TRUE(sun["distance"].is_null());
  EXPECT_EQ(sun["attenuation"].get<double>(), 1.0);  // directional: never attenuated
  EXPECT_NEAR(sun["n_dot_l"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(sun["n_dot_h"].get<double>(), 1.0, 1e-12);
  // The terms follow from the factors: diffuse = kd L att n.l, specular = ks L att (n.h)^s.
  const Json& light0 = doc["fragments"][0]["shading"]["lights"][0];
  EXPECT_NEAR(light0["diffuse"][0].get<double>(), 0.2 * 0.8, 1e-9);
  EXPECT_NEAR(light0["specular"][0].get<double>(), 0.2 * 1.8 / std::sqrt(3.6), 1e-9);
  // The story prints those factors.
  const std::string story = pixelStory(doc);
  EXPECT_NE(story.find("light 0 (point): n.l 0.8, n.h 0.9486833, attenuation 0.2 -> diffuse "
                       "(0.16, 0.16, 0.16)"),
            std::string::npos)
      << story;
  EXPECT_NE(story.find("light 1 (directional): n.l 1, n.h 1, attenuation 1"), std::string::npos)
      << story;
}

TEST(PixelHistory, PhongFactorsAreTheClosedForms) {
  const Json doc = historyAt(
      factorScene(SpecularModel::Phong, Attenuation::InverseSquare, Shading::Phong), 1, 1);
  const Json& point = factorsOf(doc, 0);
  EXPECT_NEAR(point["attenuation"].get<double>(), 1.0 / 25.0, 1e-9);  // 1 / r^2
  EXPECT_NEAR(point["n_dot_l"].get<double>(), 0.8, 1e-9);
  // r = 2 (n.l) n - l = (0, -.6, .8): r.v = .8
  EXPECT_NEAR(point["r_dot_v"].get<double>(), 0.8, 1e-9);
  EXPECT_TRUE(point["n_dot_h"].is_null());
  const std::string story = pixelStory(doc);
  EXPECT_NE(story.find("light 0 (point): n.l 0.8, r.v 0.8, attenuation 0.04"), std::string::npos)
      << story;
}

TEST(PixelHistory, FlatShadingIsEvaluatedAtTheCentroidWithTheFaceNormal) {
  const Json doc =
      historyAt(factorScene(SpecularModel::BlinnPhong, Attenuation::None, Shading::Flat), 1, 1);
  const Json& sh = doc["fragments"][0]["shading"];
  EXPECT_EQ(sh["evaluated_at"], "centroid");
  ASSERT_EQ(sh["points"].size(), 1u);
  // The centre pixel lies in triangle (-10,-10), (12,10), (-10,10): centroid (-8/3, 10/3, 0),
  // face normal (0, 0, 1).
  const Json& p = sh["points"][0];
  EXPECT_EQ(doc["fragments"][0]["triangle"], 1);
  EXPECT_NEAR(p["position"][0].get<double>(), -8.0 / 3.0, 1e-6);
  EXPECT_NEAR(p["position"][1].get<double>(), 10.0 / 3.0, 1e-6);
  EXPECT_NEAR(p["position"][2].get<double>(), 0.0, 1e-12);
  EXPECT_EQ(p["normal"], Json::array({0.0, 0.0, 1.0}));
  // The point light seen from the centroid: l = (0, 3, 4) - c, normalised.
  const double cx = p["position"][0].get<double>();
  const double cy = p["position"][1].get<double>();
  const double r = std::sqrt(cx * cx + (3.0 - cy) * (3.0 - cy) + 16.0);
  EXPECT_NEAR(sh["lights"][0]["factors"][0]["n_dot_l"].get<double>(), 4.0 / r, 1e-6);
  EXPECT_NEAR(sh["lights"][0]["factors"][0]["distance"].get<double>(), r, 1e-6);
}

TEST(PixelHistory, GouraudFactorsAtEachVertexWeightedByTheBarycentrics) {
  const Json doc =
      historyAt(factorScene(SpecularModel::BlinnPhong, Attenuation::None, Shading::Gouraud), 1, 1);
  const Json& sh = doc["fragments"][0]["shading"];
  EXPECT_EQ(sh["evaluated_at"], "vertices");
  ASSERT_EQ(sh["points"].size(), 3u);
  double weights = 0.0;
  for (int k = 0; k < 3; ++k) {
    const Json& p = sh["points"][k];
    weights += p["weight"].get<double>();
    EXPECT_EQ(p["weight"], doc["fragments"][0]["barycentric"][k]);
    // Vertex k of triangle (-10,-10), (12,10), (-10,10); the point light is at
    // r = |(0,3,4) - P| and n.l = 4 / r.
    const double px = p["position"][0].get<double>();
    const double py = p["position"][1].get<double>();
    const double corners[3][2] = {{-10.0, -10.0}, {12.0, 10.0}, {-10.0, 10.0}};
    EXPECT_EQ(px, corners[k][0]);
    EXPECT_EQ(py, corners[k][1]);
    const double r = std::sqrt(px * px + (3.0 - py) * (3.0 - py) + 16.0);
    const Json& f = sh["lights"][0]["factors"][k];
    EXPECT_NEAR(f["n_dot_l"].get<double>(), 4.0 / r, 1e-9);
    EXPECT_EQ(f["weight"], p["weight"]);
  }
  EXPECT_NEAR(weights, 1.0, 1e-12);
}

TEST(PixelHistory, ANonContributingLightStillShowsItsFactors) {
  // Gouraud lights the vertices: a point light exactly at vertex (-10, -10, 0) has no
  // direction there and contributes nothing at that vertex only.
  Scene s = litWindow();
  s.state.shading = Shading::Gouraud;
  addBigQuad(s, 0.0f, "quad");
  s.lights = {pointLight({-10.0, -10.0, 0.0})};
  Json doc = historyAt(s, 1, 1);
  const Json& factors = doc["fragments"][0]["shading"]["lights"][0]["factors"];
  ASSERT_EQ(factors.size(), 3u);
  EXPECT_FALSE(factors[0]["contributes"].get<bool>());
  EXPECT_EQ(factors[0]["distance"].get<double>(), 0.0);
  EXPECT_EQ(factors[0]["attenuation"].get<double>(), 1.0);
  EXPECT_EQ(factors[0]["n_dot_l"].get<double>(), 0.0);  // l = 0 there
  EXPECT_TRUE(factors[1]["contributes"].get<bool>());
  EXPECT_EQ(doc["fragments"][0]["shading"]["points"][0]["specular"], Json::array({0.0, 0.0, 0.0}));

  // A zero normal lights nothing at all, whatever the factors say.
  Scene z = litWindow();
  addBigQuad(z, 0.0f, "quad");
  z.objects[0].mesh.normals.assign(4, glm::vec3(0.0f));
  z.lights = {directionalLight({0.0, 0.0, -1.0})};
  doc = historyAt(z, 1, 1);
  const Json& f = factorsOf(doc, 0);
  EXPECT_FALSE(f["contributes"].get<bool>());
  EXPECT_EQ(f["n_dot_l"].get<double>(), 0.0);
  EXPECT_EQ(doc["fragments"][0]["shading"]["lights"][0]["diffuse"], Json::array({0.0, 0.0, 0.0}));
  EXPECT_EQ(doc["fragments"][0]["shading"]["lights"][0]["specular"], Json::array({0.0, 0.0, 0.0}));
}

TEST(PixelHistory, TwoQuadsInDrawOrderWithTheirDepthTests) {
  Scene s = litWindow();
  addBigQuad(s, -1.0f, "middle");  // drawn first (the eye is at z = 5)
  addBigQuad(s, 1.0f, "front");    // nearer: passes over "middle"
  addBigQuad(s, -2.0f, "back");    // farther than both: fails
  const Json doc = historyAt(s, 1, 1);
  const Json& frags = doc["fragments"];
  ASSERT_EQ(frags.size(), 3u) << doc.dump(2);
  EXPECT_EQ(frags[0]["object"], "middle");
  EXPECT_EQ(frags[0]["depth_test"]["against_source"], "clear");
  EXPECT_EQ(frags[0]["depth_test"]["result"], "pass");
  EXPECT_EQ(frags[1]["object"], "front");
  EXPECT_EQ(frags[1]["depth_test"]["result"], "pass");
  EXPECT_EQ(frags[1]["depth_test"]["against_source"], "fragment 1");
  EXPECT_EQ(frags[2]["object"], "back");
  EXPECT_EQ(frags[2]["depth_test"]["result"], "fail");
  EXPECT_EQ(frags[2]["depth_test"]["against_source"], "fragment 2");
  EXPECT_EQ(doc["final"]["object"], "front");
  EXPECT_EQ(doc["final"]["fragment"], 2);
  // Window depth of an orthographic camera: z_view = z - 5 in [-10, -1] -> (d - 1) / 9.
  EXPECT_NEAR(frags[1]["depth"]["window"].get<double>(), (4.0 - 1.0) / 9.0, 1e-6);
  const std::string story = pixelStory(doc);
  EXPECT_NE(story.find("3 fragments reached this pixel, in draw order:"), std::string::npos);
  EXPECT_NE(story.find("failed the depth test against"), std::string::npos) << story;
  EXPECT_NE(story.find("final: primitive 4 ('front')"), std::string::npos) << story;
}

TEST(PixelHistory, AnEmptyPixelKeepsTheClearValues) {
  Scene s = litWindow();
  addQuad(s, 0.2f, 1.4f, 0.2f, 1.4f, 0.0f, "corner");  // covers image pixel (2, 0) only
  s.clear_color = {0.25, 0.5, 0.75, 1.0};
  const Json doc = historyAt(s, 0, 2);
  EXPECT_TRUE(doc["fragments"].empty());
  EXPECT_EQ(doc["final"]["id"], 0);
  EXPECT_NE(pixelStory(doc).find("No fragment reached this pixel: it keeps the clear colour "
                                 "(0.25, 0.5, 0.75, 1) and the clear depth 1."),
            std::string::npos)
      << pixelStory(doc);
  EXPECT_THROW(historyAt(s, 3, 0), InputError);
}

// backendPixel on a copy of the reference frame altered at the centre pixel: the class
// and the per-pixel verdict are the comparator's.
TEST(PixelHistory, BackendVerdictsOnAlteredFrames) {
  Scene s = litWindow();
  addBigQuad(s, 0.0f, "quad");
  s.lights = {directionalLight({0.0, 0.0, -1.0})};
  const Frame ref = renderReference(s);
  const std::size_t i = ref.index(1, 1);
  const Tolerances tol = pairTolerances(ref, ref, s.tolerance);
  const double step = 1.0 / 16777215.0;

  Frame same = ref;
  Json j = backendPixel("same", ref, same, tol, i);
  EXPECT_EQ(j["class"]["visibility"], "match");
  EXPECT_EQ(j["class"]["depth"]["verdict"], "pass");
  EXPECT_EQ(j["class"]["depth"]["warn_above"].get<double>(), tol.depth.warn);
  EXPECT_EQ(j["class"]["depth"]["fail_above"].get<double>(), tol.depth.fail);
  EXPECT_EQ(j["pair_status"], "pass");

  // 1000 steps deeper: far beyond fail plus any allowance of a flat quad.
  Frame deep = ref;
  deep.depth[i] = static_cast<float>(ref.depth[i] + 1000.0 * step);
  j = backendPixel("deep", ref, deep, tol, i);
  EXPECT_EQ(j["class"]["depth"]["verdict"], "fail") << j.dump(2);
  EXPECT_GT(j["class"]["depth"]["steps"].get<double>(), 900.0);
  // fail_at = fail + (warn_at - warn): the pixel's allowance raises both thresholds.
  const double warn_at = j["class"]["depth"]["warn_above"].get<double>();
  EXPECT_GE(warn_at, tol.depth.warn);
  EXPECT_DOUBLE_EQ(j["class"]["depth"]["fail_above"].get<double>(),
                   tol.depth.fail + (warn_at - tol.depth.warn));
  EXPECT_EQ(j["pair_status"], "fail");

  // Shading: 100 units off in red fails.
  Frame red = ref;
  red.color[4 * i] += 100.0f / 255.0f;
  j = backendPixel("red", ref, red, tol, i);
  EXPECT_EQ(j["class"]["shading"]["verdict"], "fail") << j.dump(2);
  EXPECT_NEAR(j["class"]["shading"]["delta_rgba"][0].get<double>(), 100.0, 1e-3);
  // Each channel's allowance is shown where the pixel is over warn, and agrees with the
  // threshold the largest error is held to: warn_above = warn + |d|max - max_c(|d_c| - a_c).
  const Json& sh = j["class"]["shading"];
  ASSERT_TRUE(sh["allowance_rgba"].is_array()) << j.dump(2);
  double excess = -1e300;
  for (int c = 0; c < 4; ++c) {
    EXPECT_GE(sh["allowance_rgba"][c].get<double>(), 0.0);
    excess = std::max(excess, std::fabs(sh["delta_rgba"][c].get<double>()) -
                                  sh["allowance_rgba"][c].get<double>());
  }
  EXPECT_NEAR(sh["warn_above"].get<double>(), tol.shading.warn + sh["abs"].get<double>() - excess,
              1e-3);
  EXPECT_EQ(sh["base_warn"].get<double>(), tol.shading.warn);
  Json doc = historyAt(s, 1, 1);
  doc["backends"]["red"] = j;
  const std::string story = pixelStory(doc);
  EXPECT_NE(story.find("shading per channel (R, G, B, A): actual - reference (99.99"),
            std::string::npos)
      << story;
  // Within warn the comparison does not compute them: null, not made up.
  Frame close = ref;
  close.color[4 * i] += 0.005f / 255.0f;  // under the base warn, 1/64 unit in rgba32f
  j = backendPixel("close", ref, close, tol, i);
  EXPECT_EQ(j["class"]["shading"]["verdict"], "pass");
  EXPECT_TRUE(j["class"]["shading"]["allowance_rgba"].is_null()) << j.dump(2);

  // Nothing drawn where the reference drew the quad, away from every edge: a hard miss.
  Frame missing = ref;
  missing.id[i] = 0;
  j = backendPixel("missing", ref, missing, tol, i);
  EXPECT_EQ(j["class"]["visibility"], "missing_hard");
  EXPECT_FALSE(j["class"]["ambiguous"].get<bool>());
  EXPECT_TRUE(j["class"]["depth"].is_null());
}

TEST(PixelClassTable, EveryClassHasOneRowInCodeOrder) {
  for (int code = 0; code < kPixelClassCount; ++code) {
    const auto c = static_cast<PixelClass>(code);
    const PixelClassInfo& info = pixelClassInfo(c);
    EXPECT_EQ(info.value, c);
    EXPECT_STREQ(toString(c), info.label);
    // Ambiguous classes are exactly the ones whose key says so.
    EXPECT_EQ(info.ambiguous, std::string(info.key).find("_ambiguous") != std::string::npos);
  }
  EXPECT_STREQ(pixelClassInfo(PixelClass::WrongHard).key, "wrong_primitive_hard");
  EXPECT_STREQ(toString(PixelClass::MissingAmbiguous), "missing (ambiguous)");
}

TEST(PixelVerdict, RaisedThresholds) {
  const Thresholds base{4.0, 16.0};
  const Thresholds at = base.raisedBy(2.5);
  EXPECT_EQ(at.warn, 6.5);
  EXPECT_EQ(at.fail, 18.5);
  EXPECT_EQ(at.verdict(6.5), Status::Pass);  // equal to a threshold still passes
  EXPECT_EQ(at.verdict(6.6), Status::Warn);
  EXPECT_EQ(at.verdict(18.6), Status::Fail);
  EXPECT_EQ(at.verdict(std::nan("")), Status::Fail);
}

}  // namespace
}  // namespace rc
