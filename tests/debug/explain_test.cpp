// `rastercheck explain` against the reference alone: on every shading mode (and textured,
// blended and painter's scenes) the terms add up to the fragment's colour exactly as the
// reference computes it, and the final entry is what frame.exr holds (read back from a
// separate `render`); background pixels, pixels at an edge, pixels outside the image and
// the JSON keys against docs/explain.md.
#include "tests/debug/debug_test_util.h"

namespace rc::debugtest {
namespace {

// Up to `count` covered pixels spread over the image, preferring ones with several
// fragments (finite depth_gap), plus one background pixel when there is one.
std::vector<std::pair<int, int>> samplePixels(const Frame& f, std::size_t count) {
  std::vector<std::size_t> multi;
  std::vector<std::size_t> single;
  std::vector<std::size_t> background;
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    if (f.id[i] == 0) {
      background.push_back(i);
    } else if (std::isfinite(f.depth_gap[i])) {
      multi.push_back(i);
    } else {
      single.push_back(i);
    }
  }
  std::vector<std::pair<int, int>> out;
  auto take = [&](const std::vector<std::size_t>& from, std::size_t n) {
    for (std::size_t k = 0; k < n && !from.empty(); ++k) {
      const std::size_t i = from[(2 * k + 1) * from.size() / (2 * n)];
      out.emplace_back(static_cast<int>(i % f.width), static_cast<int>(i / f.width));
    }
  };
  take(multi, count / 2 + (single.empty() ? count / 2 : 0));
  take(single, multi.empty() ? count : count / 2);
  take(background, 1);
  return out;
}

struct Case {
  std::string fixture;
  std::string reference = "ref";
};

// The case's fixture and reference, not its bytes, in the test's listing (and ctest name).
void PrintTo(const Case& c, std::ostream* os) { *os << c.fixture << " against " << c.reference; }

class ExplainAddsUp : public ::testing::TestWithParam<Case> {};

TEST_P(ExplainAddsUp, TermsAddUpAndFinalIsTheFrame) {
  const Case& c = GetParam();
  const fs::path dir = scratch("addsup");
  const Frame frame = renderRef(c.fixture, dir / "ref", c.reference);
  int fragments = 0;
  int blended = 0;
  int textured = 0;
  for (const auto& [x, y] : samplePixels(frame, 4)) {
    const std::string where = c.fixture + " @ " + std::to_string(x) + "," + std::to_string(y);
    const Result r = run("explain " + c.fixture + " --pixel " + std::to_string(x) + "," +
                         std::to_string(y) + " --reference " + c.reference + " --json");
    ASSERT_EQ(r.code, 0) << where << ": " << r.err;
    const json doc = json::parse(r.out);
    checkExplain(doc, frame, where);
    for (const json& f : doc["fragments"]) {
      ++fragments;
      blended += f["blend"].is_null() ? 0 : 1;
      textured += f["shading"]["texture"].is_null() ? 0 : 1;
    }
  }
  EXPECT_GT(fragments, 0);
  if (c.fixture.find("alpha") != std::string::npos ||
      c.fixture.find("blend") != std::string::npos) {
    EXPECT_GT(blended, 0) << "no blended fragment was checked";
  }
  if (c.fixture.find("checker") != std::string::npos ||
      c.fixture.find("textured") != std::string::npos) {
    EXPECT_GT(textured, 0) << "no textured fragment was checked";
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, ExplainAddsUp,
    ::testing::Values(Case{catalog("shading/sphere_flat_low.json")},
                      Case{catalog("shading/sphere_gouraud_low.json")},
                      Case{catalog("shading/sphere_phong_low.json")},
                      Case{catalog("lighting/coloured_lights.json")},
                      Case{catalog("lighting/attenuation_inverse_square.json")},
                      Case{testData("textured_gouraud_rgba8.json")},
                      Case{catalog("transparency/alpha_quads.json")},
                      Case{testData("textured_blend_phong.json")},
                      Case{catalog("visibility/painter_three_quads.json")},
                      Case{catalog("zbuffer/cyclic_overlap_zbuffer.json"), "ref:painter"}),
    [](const ::testing::TestParamInfo<Case>& param) {
      std::string name = fs::path(param.param.fixture).stem().string() +
                         (param.param.reference == "ref" ? "" : "_painter");
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

TEST(Explain, BackgroundPixelHasNoFragmentsAndTheClearValues) {
  const fs::path dir = scratch("background");
  const std::string fixture = testData("textured_blend_phong.json");  // clear (0.1,0.2,0.3,1)
  const Frame frame = renderRef(fixture, dir / "ref");
  ASSERT_EQ(frame.id[frame.index(0, 0)], 0u);
  const Result r = run("explain " + fixture + " --pixel 0,0 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(r.out);
  EXPECT_TRUE(doc["fragments"].empty());
  EXPECT_EQ(doc["final"]["id"], 0);
  EXPECT_TRUE(doc["final"]["fragment"].is_null());
  EXPECT_TRUE(doc["final"]["object"].is_null());
  const double clear[4] = {0.1, 0.2, 0.3, 1.0};
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(doc["final"]["color"][c].get<double>(), static_cast<float>(clear[c]));
  EXPECT_EQ(doc["final"]["depth"].get<double>(), 1.0);
  EXPECT_TRUE(doc["depth_gap"].is_null());
  checkExplain(doc, frame, "background");
  const Result text = run("explain " + fixture + " --pixel 0,0");
  EXPECT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("No fragment reached this pixel"), std::string::npos) << text.out;
  fs::remove_all(dir);
}

TEST(Explain, PixelOutsideTheImageExitsTwoWithOneLine) {
  const std::string fixture = catalog("shading/sphere_flat_low.json");  // 160x160
  for (const char* pixel : {"160,0", "0,160", "-1,5"}) {
    const Result r = run(std::string("explain ") + fixture + " --pixel " + pixel + " --json");
    EXPECT_EQ(r.code, 2) << pixel;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("outside the 160x160 image"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  for (const char* pixel : {"5", "1.5,2"}) {
    const Result r = run(std::string("explain ") + fixture + " --pixel " + pixel);
    EXPECT_EQ(r.code, 2) << pixel;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--pixel"), std::string::npos) << r.err;
  }
  EXPECT_EQ(run("explain " + fixture + " --pixel 1,1 --backends vulkan").code, 2);
  EXPECT_EQ(run("explain " + fixture + " --pixel 1,1 --reference gl").code, 2);
  EXPECT_EQ(run("explain /nonexistent.json --pixel 1,1").code, 2);
}

TEST(Explain, AtAnEdgeTheUncertaintyIsReported) {
  // Pixels whose centre is within a tenth of a pixel of a triangle edge.
  const fs::path dir = scratch("edge");
  const std::string fixture = catalog("coverage/triangle_fan.json");
  const Frame frame = renderRef(fixture, dir / "ref");
  int checked = 0;
  for (std::size_t i = 0; i < frame.pixelCount() && checked < 3; i += 37) {
    if (frame.id[i] == 0 || !(frame.edge_dist[i] < 0.1f)) continue;
    const int x = static_cast<int>(i % frame.width);
    const int y = static_cast<int>(i / frame.width);
    const Result r = run("explain " + fixture + " --pixel " + std::to_string(x) + "," +
                         std::to_string(y) + " --backends ref:subpixel=4 --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const json doc = json::parse(r.out);
    checkExplain(doc, frame, "edge " + std::to_string(x) + "," + std::to_string(y));
    EXPECT_LT(doc["edge_dist"].get<double>(), 0.1);
    EXPECT_FALSE(doc["fragments"].empty());
    // The other side's class there is a match or an excused (ambiguous) mismatch.
    const json& c = doc["backends"]["ref:subpixel=4"]["class"];
    EXPECT_TRUE(c["visibility"] == "match" || c["ambiguous"].get<bool>()) << c.dump();
    ++checked;
  }
  EXPECT_EQ(checked, 3);
  fs::remove_all(dir);
}

TEST(Explain, TextReadsLikeAStory) {
  const Result r = run("explain " + catalog("transparency/alpha_quads.json") + " --pixel 70,70");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* phrase :
       {"pixel (70,70) in image coordinates, GL window (70,49)", "fragment 1: primitive 3",
        "of 'wall'", "passed the depth test against the clear depth 1",
        "passed the depth test against 0.8641975 (stored by fragment 1)", "depth writes off",
        "blended over (0.8, 0.8, 0.8, 1) with alpha 0.4", "final: primitive 1 ('red')",
        "(written by fragment 3)", "uncertainty: edge_dist"})
    EXPECT_NE(r.out.find(phrase), std::string::npos) << phrase << "\n" << r.out;
  const Result failed =
      run("explain " + catalog("shading/sphere_phong_low.json") + " --pixel 64,64");
  EXPECT_NE(failed.out.find("2 fragments reached this pixel"), std::string::npos) << failed.out;
}

TEST(Explain, ReferenceBackendsAreComparedAtThePixel) {
  // ref:painter on a cyclic overlap: somewhere the painter's order shows the wrong stick,
  // and explain must call that pixel a hard wrong_primitive there.
  const fs::path dir = scratch("painter");
  const std::string fixture = catalog("zbuffer/cyclic_overlap_zbuffer.json");
  const Frame ref = renderRef(fixture, dir / "ref");
  const Frame painter = renderRef(fixture, dir / "painter", "ref:painter");
  std::size_t hit = ref.pixelCount();
  for (std::size_t i = 0; i < ref.pixelCount(); ++i)
    if (ref.id[i] != 0 && painter.id[i] != 0 && ref.id[i] != painter.id[i] &&
        ref.edge_dist[i] >= 1.0f) {
      hit = i;
      break;
    }
  ASSERT_LT(hit, ref.pixelCount());
  const int x = static_cast<int>(hit % ref.width);
  const int y = static_cast<int>(hit / ref.width);
  const Result r = run("explain " + fixture + " --pixel " + std::to_string(x) + "," +
                       std::to_string(y) + " --backends ref:painter,ref --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(r.out);
  const json& p = doc["backends"]["ref:painter"];
  EXPECT_EQ(p["id"].get<std::uint32_t>(), painter.id[hit]);
  EXPECT_EQ(static_cast<float>(p["depth"].get<double>()), painter.depth[hit]);
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(static_cast<float>(p["color"][c].get<double>()), painter.color[4 * hit + c]);
  EXPECT_EQ(p["class"]["visibility"], "wrong_primitive_hard");
  EXPECT_EQ(p["pair_status"], "fail");
  EXPECT_TRUE(p["class"]["depth"].is_null());
  const json& same = doc["backends"]["ref"];
  EXPECT_EQ(same["class"]["visibility"], "match");
  EXPECT_EQ(same["class"]["depth"]["steps"].get<double>(), 0.0);
  EXPECT_EQ(same["class"]["shading"]["abs"].get<double>(), 0.0);
  EXPECT_EQ(same["class"]["shading"]["verdict"], "pass");
  fs::remove_all(dir);
}

// At a crossing of the cyclic sticks the A-buffer list is far to near, disagrees with the
// draw order, and ends in ref:abuffer's colour and id there.
TEST(Explain, ABufferListIsSortedAndEndsInTheExactColour) {
  const Result r = run("explain " + catalog("transparency/oit_cyclic.json") +
                       " --pixel 57,93 --backends ref:abuffer --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(r.out);
  const json& list = doc["abuffer"]["fragments"];
  ASSERT_EQ(list.size(), 2u);
  EXPECT_GT(list[0]["window_z"].get<double>(), list[1]["window_z"].get<double>());
  EXPECT_FALSE(doc["abuffer"]["draw_order_matches"].get<bool>());
  const json& exact = doc["backends"]["ref:abuffer"];
  EXPECT_EQ(exact["id"], list[1]["primitive"]);
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(static_cast<float>(exact["color"][c].get<double>()),
              static_cast<float>(list[1]["color_after"][c].get<double>()));
  EXPECT_NE(doc["final"]["id"], exact["id"]);  // the draw order's top fragment differs
  // Without ref:abuffer there is no list.
  const Result plain =
      run("explain " + catalog("transparency/oit_cyclic.json") + " --pixel 57,93 --json");
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_FALSE(json::parse(plain.out).contains("abuffer"));
}

TEST(Explain, ALinePixelTellsItsSegmentTheRuleAndTheParameter) {
  // Pixel (95, 52) of the star: segment 2 (primitive 3) passes through it, inside.
  const Result r =
      run("explain " + catalog("lines/star_octants.json") + " --pixel 95,52 --backends ref --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(r.out);
  ASSERT_FALSE(doc["fragments"].empty());
  const json& f = doc["fragments"][0];
  EXPECT_EQ(f["primitive_kind"], "lines");
  EXPECT_EQ(f["line"]["kind"], "segment");
  EXPECT_EQ(f["line"]["rule"], "diamond-exit");
  const double t = f["line"]["t"].get<double>();
  EXPECT_GT(t, 0.0);
  EXPECT_LT(t, 1.0);
  // The barycentrics are the parameter, perspective-free here (orthographic camera).
  EXPECT_NEAR(f["barycentric"][1].get<double>(), t, 1e-9);
  EXPECT_GT(f["line"]["margin"].get<double>(), 0.0);
  EXPECT_LT(f["line"]["margin"].get<double>(), 0.5);
  const Result text =
      run("explain " + catalog("lines/star_octants.json") + " --pixel 95,52 --backends ref");
  EXPECT_NE(text.out.find("segment 2 of 'star'"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("diamond-exit rule"), std::string::npos) << text.out;
}

TEST(Explain, JsonKeysAreTheDocumentedOnes) {
  const std::set<std::string> documented = documentedKeys();
  ASSERT_GT(documented.size(), 100u) << "docs/explain.md's key table was not found";
  std::set<std::string> seen;
  const std::vector<std::string> calls = {
      testData("textured_blend_phong.json") +
          " --pixel 32,24 --backends ref:subpixel=4,ref:painter",
      catalog("shading/sphere_gouraud_low.json") + " --pixel 70,70",
      catalog("transparency/alpha_quads.json") + " --pixel 70,70",
      catalog("shading/sphere_flat_low.json") + " --pixel 0,0 --backends ref",
      catalog("transparency/oit_cyclic.json") + " --pixel 57,93 --backends ref:abuffer",
      catalog("fragment-ops/stencil_portal.json") + " --pixel 80,60 --backends ref",
      catalog("fragment-ops/decal_offset.json") + " --pixel 90,70 --backends ref",
      catalog("mipmap/level_colours.json") + " --pixel 80,60 --backends ref",
      catalog("lines/star_octants.json") + " --pixel 95,52 --backends ref",
      catalog("lines/point_sizes.json") + " --pixel 38,101 --backends ref",
      catalog("shadow/spot_perspective_pcf.json") + " --pixel 80,110 --backends ref"};
  for (const std::string& call : calls) {
    const Result r = run("explain " + call + " --json");
    ASSERT_EQ(r.code, 0) << call << ": " << r.err;
    collectKeys(json::parse(r.out), "", seen);
  }
  for (const std::string& k : seen) EXPECT_TRUE(documented.count(k)) << "undocumented key " << k;
  // Every documented key appears (the error entry needs a failing backend, the base
  // thresholds a GL backend over its shading warn threshold: GL tests).
  for (const std::string& k : documented) {
    if (k != "backends.SPEC.error" && k != "backends.SPEC.class.shading.base_warn" &&
        k != "backends.SPEC.class.shading.base_fail") {
      EXPECT_TRUE(seen.count(k)) << "documented key never seen " << k;
    }
  }
}

}  // namespace
}  // namespace rc::debugtest
