// debug/probes.h: which probes a fixture gets, what each changes, and what a failure
// needs given which probes still fail.
#include "debug/probes.h"

#include <algorithm>

#include <gtest/gtest.h>

namespace rc {
namespace {

using nlohmann::json;

json baseFixture() {
  return json::parse(R"({
    "format": "rastercheck-scene/1", "name": "t/probe",
    "image": {"width": 8, "height": 8},
    "camera": {"projection": "perspective", "eye": [0, 0, 5], "target": [0, 0, 0],
               "up": [0, 1, 0], "fovy_deg": 45, "near": 0.1, "far": 100},
    "materials": {"m": {"diffuse": [1, 0, 0]}},
    "objects": [{"material": "m", "mesh": {"generator": "cube"}}]
  })");
}

const Probe* find(const std::vector<Probe>& probes, const std::string& key) {
  const auto it =
      std::find_if(probes.begin(), probes.end(), [&](const Probe& p) { return p.key == key; });
  return it == probes.end() ? nullptr : &*it;
}

std::vector<std::string> keys(const std::vector<Probe>& probes) {
  std::vector<std::string> out;
  for (const Probe& p : probes) out.push_back(p.key);
  return out;
}

TEST(Probes, FirstIsTheFixtureUnchangedAndNamesAreUnique) {
  const json f = baseFixture();
  const std::vector<Probe> probes = makeProbes(f);
  ASSERT_FALSE(probes.empty());
  EXPECT_EQ(probes[0].key, "");
  json unchanged = probes[0].fixture;
  EXPECT_EQ(unchanged["name"], "t/probe/probe/unchanged");
  unchanged["name"] = f["name"];
  EXPECT_EQ(unchanged, f);
  std::vector<std::string> names;
  for (const Probe& p : probes) names.push_back(p.fixture["name"].get<std::string>());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end());
}

TEST(Probes, DefaultsAreProbedAtTheirAlternativeOnlyWhereTheyCanMatter) {
  // No lights, no texture, opaque: only the keys that change what any scene shows.
  const std::vector<Probe> probes = makeProbes(baseFixture());
  EXPECT_EQ(keys(probes), (std::vector<std::string>{"", "depth_test", "depth_format",
                                                    "color_format", "visibility"}));
  const Probe* depth = find(probes, "depth_format");
  ASSERT_NE(depth, nullptr);
  EXPECT_EQ(depth->fixture["state"]["depth_format"], "d32f");
  EXPECT_EQ(depth->involves, "depth_format=d24");
  EXPECT_EQ(depth->change, "depth_format d24 -> d32f");
  EXPECT_EQ(find(probes, "depth_test")->involves, "depth_test=true");
  EXPECT_EQ(find(probes, "depth_test")->fixture["state"]["depth_test"], false);
}

TEST(Probes, NonDefaultValuesAreProbedAtTheDefault) {
  json f = baseFixture();
  f["state"] = {{"depth_format", "d16"},
                {"cull", "back"},
                {"front_face", "cw"},
                {"blend", "alpha"},
                {"visibility", "painter"}};
  const std::vector<Probe> probes = makeProbes(f);
  EXPECT_EQ(find(probes, "depth_format")->fixture["state"]["depth_format"], "d24");
  EXPECT_EQ(find(probes, "depth_format")->involves, "depth_format=d16");
  EXPECT_EQ(find(probes, "cull")->fixture["state"]["cull"], "none");
  EXPECT_EQ(find(probes, "blend")->fixture["state"]["blend"], "none");
  EXPECT_EQ(find(probes, "visibility")->involves, "visibility=painter");
  // Flipping the front face under culling draws other triangles: never a probe.
  EXPECT_EQ(find(probes, "front_face"), nullptr);
  // Everything else of the document is kept.
  EXPECT_EQ(find(probes, "cull")->fixture["state"]["depth_format"], "d16");
  EXPECT_EQ(find(probes, "cull")->fixture["objects"], f["objects"]);
}

TEST(Probes, LightingKeysNeedLightsAndTextureKeysATexture) {
  json f = baseFixture();
  f["lights"] = json::array({{{"type", "directional"}, {"direction", {0, -1, 0}}}});
  std::vector<Probe> probes = makeProbes(f);
  EXPECT_NE(find(probes, "shading"), nullptr);
  EXPECT_NE(find(probes, "specular_model"), nullptr);
  EXPECT_EQ(find(probes, "attenuation"), nullptr) << "directional lights do not attenuate";
  ASSERT_NE(find(probes, "lights"), nullptr);
  EXPECT_TRUE(find(probes, "lights")->fixture["lights"].empty());
  EXPECT_EQ(find(probes, "texture_filter"), nullptr);

  f["lights"].push_back({{"type", "point"}, {"position", {1, 2, 3}}});
  f["materials"]["m"]["texture"] = "textures/a.png";
  probes = makeProbes(f);
  EXPECT_EQ(find(probes, "attenuation")->fixture["state"]["attenuation"], "inverse");
  EXPECT_EQ(find(probes, "texture_filter")->fixture["state"]["texture_filter"], "linear");
  EXPECT_EQ(find(probes, "texture_wrap")->fixture["state"]["texture_wrap"], "clamp");
  ASSERT_NE(find(probes, "texture"), nullptr);
  EXPECT_FALSE(find(probes, "texture")->fixture["materials"]["m"].contains("texture"));
  EXPECT_EQ(find(probes, "texture")->involves, "texture");
}

TEST(Probes, TransparencyOnlyWhenBlendedMaterialsAreTransparent) {
  json f = baseFixture();
  f["materials"]["m"]["opacity"] = 0.5;
  EXPECT_EQ(find(makeProbes(f), "transparency"), nullptr) << "blend none: opacity unused";
  f["state"]["blend"] = "alpha";
  const std::vector<Probe> probes = makeProbes(f);
  const Probe* p = find(probes, "transparency");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->fixture["materials"]["m"]["opacity"], 1.0);
}

TEST(Probes, OnlyWhatCanChangeTheFailingClass) {
  json f = baseFixture();
  f["lights"] = json::array({{{"type", "point"}, {"position", {1, 2, 3}}}});
  f["materials"]["m"]["texture"] = "textures/a.png";
  f["state"] = {{"blend", "alpha"}, {"cull", "back"}};
  EXPECT_EQ(
      keys(makeProbes(f, "shading")),
      (std::vector<std::string>{"", "shading", "specular_model", "attenuation", "color_format",
                                "blend", "texture_filter", "texture_wrap", "texture", "lights"}));
  EXPECT_EQ(
      keys(makeProbes(f, "depth")),
      (std::vector<std::string>{"", "depth_test", "depth_format", "cull", "blend", "visibility"}));
  EXPECT_EQ(keys(makeProbes(f, "visibility")), keys(makeProbes(f, "depth")));
  EXPECT_EQ(makeProbes(f).size(), 14u) << "no class: all 11 state keys, texture, lights";
}

TEST(Probes, InvolvedAreThoseWhoseProbePasses) {
  json f = baseFixture();
  f["state"] = {{"depth_format", "d16"}};
  const std::vector<Probe> probes = makeProbes(f);
  std::vector<std::optional<bool>> still(probes.size(), true);
  for (std::size_t i = 0; i < probes.size(); ++i) {
    if (probes[i].key == "depth_format") still[i] = false;
    if (probes[i].key == "visibility") still[i] = std::nullopt;  // could not be compared
  }
  EXPECT_EQ(involvedIn(probes, still), std::vector<std::string>{"depth_format=d16"});
  // The fixture itself no longer failing (or unknown): nothing can be concluded.
  still[0] = false;
  EXPECT_TRUE(involvedIn(probes, still).empty());
  still[0] = std::nullopt;
  EXPECT_TRUE(involvedIn(probes, still).empty());
}

TEST(Probes, RelativePathsBecomeAbsolute) {
  json f = baseFixture();
  f["materials"]["m"]["texture"] = "textures/a.png";
  f["materials"]["n"] = {{"texture", "/abs/b.png"}};
  f["objects"].push_back({{"mesh", {{"file", "../meshes/x.obj"}}}});
  absolutizePaths(f, "/data/scenes");
  EXPECT_EQ(f["materials"]["m"]["texture"], "/data/scenes/textures/a.png");
  EXPECT_EQ(f["materials"]["n"]["texture"], "/abs/b.png");
  EXPECT_EQ(f["objects"][1]["mesh"]["file"], "/data/meshes/x.obj");
  EXPECT_EQ(f["objects"][0]["mesh"]["generator"], "cube");
}

}  // namespace
}  // namespace rc
