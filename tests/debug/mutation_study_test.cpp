// debug/mutation_study.h: how each fault is set for a scene, the verdict of one (scene,
// fault) from its three comparisons, and the tallies (no rendering).
#include "debug/mutation_study.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fixtures/errors.h"

namespace rc {
namespace {

using ::testing::HasSubstr;

TEST(MutationStudy, TheFaultsAndTheirClasses) {
  std::vector<std::pair<std::string, std::string>> got;
  for (const MutationFault& f : mutationFaults()) got.emplace_back(f.name, f.cls);
  EXPECT_EQ(got, (std::vector<std::pair<std::string, std::string>>{{"light_scale", "shading"},
                                                                   {"depth_bias", "depth"},
                                                                   {"drop_primitive", "visibility"},
                                                                   {"move_vertex", "visibility"},
                                                                   {"texel_offset", "shading"},
                                                                   {"blend_factor", "shading"},
                                                                   {"depth_func", "visibility"},
                                                                   {"stencil_op", "depth"},
                                                                   {"blend_function", "shading"},
                                                                   {"scissor_shift", "visibility"},
                                                                   {"lod_shift", "shading"},
                                                                   {"lod_weight", "shading"},
                                                                   {"move_line_end", "visibility"},
                                                                   {"move_point", "visibility"},
                                                                   {"shadow_shift", "shading"},
                                                                   {"shadow_compare", "shading"},
                                                                   {"shadow_bias", "shading"}}));
  EXPECT_EQ(std::string(mutationFault("depth_bias").cls), "depth");
  EXPECT_THROW(mutationFault("shift_x"), InputError);
}

TEST(MutationStudy, LineAndPointFaultsPickTheirOwnKindOfPrimitive) {
  MutationScene scene;
  scene.visible_ids = {3, 9, 12, 20};
  scene.line_ids = {9, 10};
  scene.point_ids = {20, 21};
  for (std::uint64_t index = 0; index < 20; ++index) {
    EXPECT_EQ(faultSetting(mutationFault("move_line_end"), scene, 1, index), "move_line_end=9");
    EXPECT_EQ(faultSetting(mutationFault("move_point"), scene, 1, index), "move_point=20");
    const std::string moved = faultSetting(mutationFault("move_vertex"), scene, 1, index);
    EXPECT_TRUE(moved == "move_vertex=3" || moved == "move_vertex=12") << moved;
  }
  scene.line_ids.clear();
  EXPECT_EQ(faultSetting(mutationFault("move_line_end"), scene, 1, 0), "");
}

TEST(MutationStudy, SettingsFollowWhatTheSceneOffers) {
  MutationScene scene;
  scene.visible_ids = {3, 9, 12};
  EXPECT_EQ(faultSetting(mutationFault("light_scale"), scene, 1, 0), "light_scale=1.01");
  EXPECT_EQ(faultSetting(mutationFault("depth_bias"), scene, 1, 0), "depth_bias=64");
  scene.depth_format = "d16";
  EXPECT_EQ(faultSetting(mutationFault("depth_bias"), scene, 1, 0), "depth_bias=8");
  EXPECT_EQ(faultSetting(mutationFault("texel_offset"), scene, 1, 0), "") << "no texture";
  EXPECT_EQ(faultSetting(mutationFault("blend_factor"), scene, 1, 0), "") << "no blending";
  scene.textured = scene.blended = true;
  EXPECT_EQ(faultSetting(mutationFault("texel_offset"), scene, 1, 0), "texel_offset=1");
  EXPECT_EQ(faultSetting(mutationFault("blend_factor"), scene, 1, 0), "blend_factor=one");
  EXPECT_EQ(faultSetting(mutationFault("lod_weight"), scene, 1, 0), "") << "no level blend";
  scene.lod = true;
  EXPECT_EQ(faultSetting(mutationFault("lod_shift"), scene, 1, 0), "lod_shift=1");
  EXPECT_EQ(faultSetting(mutationFault("lod_weight"), scene, 1, 0), "") << "one level at a time";
  scene.lod_blend = true;
  EXPECT_EQ(faultSetting(mutationFault("lod_weight"), scene, 1, 0), "lod_weight=inverted");
  EXPECT_EQ(faultSetting(mutationFault("shadow_shift"), scene, 1, 0), "") << "no shadow lookup";
  EXPECT_EQ(faultSetting(mutationFault("shadow_compare"), scene, 1, 0), "");
  scene.shadowed = true;
  EXPECT_EQ(faultSetting(mutationFault("shadow_shift"), scene, 1, 0), "shadow_shift=1");
  EXPECT_EQ(faultSetting(mutationFault("shadow_compare"), scene, 1, 0), "shadow_compare=inverted");
  EXPECT_EQ(faultSetting(mutationFault("shadow_bias"), scene, 1, 0), "") << "no bias to drop";
  scene.shadow_bias = true;
  EXPECT_EQ(faultSetting(mutationFault("shadow_bias"), scene, 1, 0), "shadow_bias=dropped");
}

TEST(MutationStudy, PrimitivesAreDrawnFromTheVisibleOnesReproducibly) {
  MutationScene scene;
  scene.visible_ids = {3, 9, 12, 40, 41};
  std::set<std::string> seen;
  for (std::uint64_t index = 0; index < 64; ++index) {
    const std::string s = faultSetting(mutationFault("drop_primitive"), scene, 5, index);
    EXPECT_EQ(s, faultSetting(mutationFault("drop_primitive"), scene, 5, index));
    seen.insert(s);
  }
  EXPECT_EQ(seen,
            (std::set<std::string>{"drop_primitive=3", "drop_primitive=9", "drop_primitive=12",
                                   "drop_primitive=40", "drop_primitive=41"}))
      << "every visible primitive is drawn sometimes, never another";
  EXPECT_THAT(faultSetting(mutationFault("move_vertex"), scene, 5, 0), HasSubstr("move_vertex="));
  scene.visible_ids.clear();
  EXPECT_EQ(faultSetting(mutationFault("drop_primitive"), scene, 5, 0), "") << "nothing drawn";
}

TEST(MutationStudy, VerdictsFromTheThreeComparisons) {
  using V = MutationVerdict;
  const std::set<std::string> none, depth{"depth"}, both{"depth", "visibility"};
  EXPECT_EQ(judgeMutation("depth", depth, depth, depth), V::ControlFails);
  EXPECT_EQ(judgeMutation("depth", none, none, depth), V::NoEffect);
  EXPECT_EQ(judgeMutation("depth", none, {"visibility"}, both), V::NoEffect)
      << "an effect in another class only does not count";
  EXPECT_EQ(judgeMutation("depth", none, both, both), V::Caught);
  EXPECT_EQ(judgeMutation("depth", none, depth, {"visibility"}), V::Missed)
      << "caught only in another class is missed";
  EXPECT_EQ(judgeMutation("depth", {"shading"}, depth, depth), V::Caught)
      << "a control failure elsewhere does not matter";
}

TEST(MutationStudy, TalliesCountOnlyScenesWithAnEffect) {
  auto result = [](const char* fault, MutationVerdict v) {
    MutationResult r;
    r.fixture = "random/s1/00001";
    r.fixture_file = "/s/s1-00001.json";
    r.backend = "gl:egl:llvmpipe";
    r.fault = fault;
    r.setting = std::string(fault) + "=1";
    r.verdict = v;
    r.effect_fails = {"depth"};
    r.note = "FAIL ...";
    return r;
  };
  const std::vector<MutationResult> results = {
      result("depth_bias", MutationVerdict::Caught),
      result("depth_bias", MutationVerdict::Caught),
      result("depth_bias", MutationVerdict::Missed),
      result("depth_bias", MutationVerdict::NoEffect),
      result("depth_bias", MutationVerdict::ControlFails),
      result("texel_offset", MutationVerdict::NotApplicable),
  };
  const MutationTallies t = tallyMutations(results);
  const MutationTally& depth = t.at("gl:egl:llvmpipe").at("depth_bias");
  EXPECT_EQ(depth.scenes, 5u);
  EXPECT_EQ(depth.counted(), 3u);
  EXPECT_DOUBLE_EQ(depth.caughtFraction(), 2.0 / 3.0);
  ASSERT_EQ(depth.missed.size(), 1u);
  EXPECT_EQ(t.at("gl:egl:llvmpipe").at("texel_offset").counted(), 0u);
  EXPECT_DOUBLE_EQ(t.at("gl:egl:llvmpipe").at("texel_offset").caughtFraction(), 1.0);

  const std::string md = mutationMarkdown(t, "rastercheck campaign --mutations", 5, 5, true);
  EXPECT_THAT(md, HasSubstr("| `depth_bias` ("));
  EXPECT_THAT(md, HasSubstr("| depth | 5 | 0 | 1 | 1 | 3 | 2 | 1 | 0 | 66.7 % |"));
  EXPECT_THAT(md, HasSubstr("- `random/s1/00001` with `depth_bias=1`"));
  const nlohmann::json j = mutationJson(t, results, "cmd", {}, 5, 5, true);
  EXPECT_EQ(j["backends"]["gl:egl:llvmpipe"]["depth_bias"]["counted"], 3);
  EXPECT_EQ(j["backends"]["gl:egl:llvmpipe"]["depth_bias"]["verdicts"]["missed"], 1);
  EXPECT_EQ(mutationResultFromJson(j["results"][2], "x").verdict, MutationVerdict::Missed);
  EXPECT_EQ(toJson(mutationResultFromJson(j["results"][0], "x")), j["results"][0]);
  nlohmann::json bad = j["results"][0];
  bad["verdict"] = "perhaps";
  EXPECT_THROW(mutationResultFromJson(bad, "x"), InputError);
}

// Four pixels in a row: the reference (with its uncertainty channels), the clean and the
// faulted driver frame.
struct StudyFrames {
  Frame ref;
  Frame clean;
  Frame faulted;
};
StudyFrames studyFrames() {
  const float clear[4] = {0, 0, 0, 1};
  StudyFrames f;
  f.ref.allocate(4, 1, clear, 1.0f, true);
  f.clean.allocate(4, 1, clear, 1.0f, false);
  f.faulted.allocate(4, 1, clear, 1.0f, false);
  return f;
}

// The effect comparison sees the faulted frame only where the reference shows the clean
// frame's primitive: elsewhere depth and colour are the clean frame's, ids are the faulted.
TEST(MutationStudy, TheEffectFrameKeepsOnlyWhatTheReferenceJudges) {
  StudyFrames frames = studyFrames();
  auto& [ref, clean, faulted] = frames;
  ref.id = {1, 1, 2, 0};    // pixel 2: another primitive; pixel 3: background
  clean.id = {1, 1, 1, 1};  // the driver covers all four with primitive 1
  faulted.id = {1, 3, 1, 1};
  for (std::size_t i = 0; i < 4; ++i) {
    ref.depth[i] = clean.depth[i] = 0.5f;
    faulted.depth[i] = 0.5f + 0.1f * static_cast<float>(i + 1);
    ref.color[4 * i] = clean.color[4 * i] = 0.25f;
    faulted.color[4 * i] = 0.75f;
  }
  const Frame seen = effectFrame(clean, faulted, ref);
  EXPECT_EQ(seen.id, faulted.id);
  EXPECT_EQ(seen.depth, (std::vector<float>{faulted.depth[0], faulted.depth[1], 0.5f, 0.5f}));
  EXPECT_EQ(seen.color[0], 0.75f);
  EXPECT_EQ(seen.color[4], 0.75f);
  EXPECT_EQ(seen.color[8], 0.25f);
  EXPECT_EQ(seen.color[12], 0.25f);
  Frame small;
  const float clear[4] = {0, 0, 0, 1};
  small.allocate(2, 1, clear, 1.0f, false);
  EXPECT_THROW(effectFrame(clean, small, ref), InputError);
}

// Where the clean driver is already off the reference, the effect is the fault's change
// less that distance, towards the clean value: what is left is at least as far from the
// reference (scene 00048 of s20261227: reference 236, clean 235, faulted 239 counted a
// 4-unit effect that was 3 units from the reference, inside its allowance).
TEST(MutationStudy, TheEffectIsNetOfTheCleanDriversOwnDeviation) {
  StudyFrames frames = studyFrames();
  auto& [ref, clean, faulted] = frames;
  ref.id = clean.id = faulted.id = {1, 1, 1, 1};
  const float r[4] = {236, 236, 236, 236};
  const float c[4] = {235, 237, 236, 238};  // off by -1, +1, 0, +2
  const float f[4] = {239, 239, 233, 239};  // the fault: +4, +2, -3, +1
  for (std::size_t i = 0; i < 4; ++i) {
    ref.color[4 * i + 1] = r[i] / 255.0f;
    clean.color[4 * i + 1] = c[i] / 255.0f;
    faulted.color[4 * i + 1] = f[i] / 255.0f;
    ref.depth[i] = 0.5f;
    clean.depth[i] = 0.5f + 0.01f * static_cast<float>(i);
    faulted.depth[i] = 0.75f;
  }
  const Frame seen = effectFrame(clean, faulted, ref);
  const float want[4] = {238, 238, 233, 238};  // 235 + (4 - 1), 237 + (2 - 1), 236 - 3, 238
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(seen.color[4 * i + 1] * 255.0f, want[i], 1e-3) << i;
    // Depth: 0.25 - 0.01 i moved, less the clean driver's 0.01 i off the reference.
    EXPECT_NEAR(seen.depth[i], 0.75f - 0.01f * static_cast<float>(i), 1e-6) << i;
    // Never further from the reference than the faulted value (it is the lower bound of
    // how far the faulted value is).
    EXPECT_LE(std::fabs(seen.color[4 * i + 1] - ref.color[4 * i + 1]),
              std::fabs(faulted.color[4 * i + 1] - ref.color[4 * i + 1]) + 1e-6f)
        << i;
  }
  // A NaN the fault made is kept (the comparator counts it), whatever the clean driver did.
  faulted.color[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(std::isnan(effectFrame(clean, faulted, ref).color[1]));
}

}  // namespace
}  // namespace rc
