// Checks of the catalog itself, without GL: the expectations file is valid (and its
// validator catches each kind of mistake), the catalog covers every required tag with at
// least 40 described fixtures, and fixtures/README.md is what
// scripts/gen-fixture-readme.sh makes of the catalog today.

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "fixtures/catalog.h"
#include "fixtures/loader.h"
#include "reference/reference_renderer.h"
#include "tests/conformance/conformance_support.h"
#include "tests/support/command.h"

namespace fs = std::filesystem;
using namespace rc;
using namespace rc::conformance;

namespace {

// The topics of the lecture notes that the issue asks the catalog to cover.
const std::vector<std::string> kRequiredTags = {"coverage",
                                                "fill-rule",
                                                "subpixel",
                                                "clipping",
                                                "near-plane",
                                                "culling",
                                                "zbuffer",
                                                "painter",
                                                "depth-precision",
                                                "depth-func",
                                                "stencil",
                                                "scissor",
                                                "blend-modes",
                                                "polygon-offset",
                                                "color-mask",
                                                "mipmap",
                                                "perspective",
                                                "orthographic",
                                                "flat",
                                                "gouraud",
                                                "phong",
                                                "blinn-phong",
                                                "ambient",
                                                "diffuse",
                                                "specular",
                                                "point-light",
                                                "directional-light",
                                                "attenuation",
                                                "normal-matrix",
                                                "vertex-normals",
                                                "texture",
                                                "transparency",
                                                "real-mesh",
                                                "oit",
                                                "msaa"};

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += "\n  " + l;
  return out;
}

}  // namespace

TEST(Expectations, FileIsValid) {
  const SuiteExpectations& e = expectations();
  EXPECT_TRUE(e.errors.empty()) << expectationsFile().string() << ":" << joinLines(e.errors);
}

TEST(Expectations, EntriesMustNameCatalogFixturesAndSuiteBackends) {
  const Expectations parsed = parseExpectations(nlohmann::json::parse(R"({"expectations": [
      {"fixture": "depth/zfight_d16", "backend": "gl:egl:softpipe", "class": "depth",
       "reason": "r"},
      {"fixture": "depth/nope", "backend": "gl:egl:llvmpipe", "class": "depth", "reason": "r"},
      {"fixture": "*", "backend": "gl:egl:llvmpipes", "class": "depth", "reason": "r"},
      {"fixture": "depth/*", "backend": "gl:*:softpipe", "class": "depth", "reason": "r"}]})"),
                                                "test");
  const SuiteExpectations e =
      checkExpectations(parsed, {"depth/zfight_d16"}, {"gl:egl:llvmpipe", "gl:egl:softpipe"});
  ASSERT_EQ(e.errors.size(), 2u) << joinLines(e.errors);
  EXPECT_NE(e.errors[0].find("expectations[1] (expectations[1]).fixture: no fixture named "
                             "\"depth/nope\""),
            std::string::npos)
      << e.errors[0];
  EXPECT_NE(e.errors[1].find("\"gl:egl:llvmpipes\" matches none"), std::string::npos)
      << e.errors[1];
}

TEST(Catalog, CoversEveryRequiredTagWithDescribedFixtures) {
  std::map<std::string, int> per_tag;
  std::set<std::string> names;
  int count = 0;
  for (const fs::path& file : findFixtures({catalogDir()})) {
    const Scene scene = loadScene(file);
    ++count;
    EXPECT_TRUE(names.insert(scene.name).second) << "two fixtures named " << scene.name;
    EXPECT_FALSE(scene.description.empty()) << scene.name << " has no description";
    EXPECT_EQ(scene.description.find('\n'), std::string::npos)
        << scene.name << ": the description must be one line";
    // The first part of the name is the topic folder the fixture lives in.
    const std::string folder = file.parent_path().filename().string();
    EXPECT_EQ(scene.name.substr(0, scene.name.find('/')), folder) << file;
    for (const std::string& t : scene.tags) ++per_tag[t];
  }
  EXPECT_GE(count, 40);
  for (const std::string& tag : kRequiredTags)
    EXPECT_GT(per_tag[tag], 0) << "no fixture is tagged " << tag;
}

TEST(Catalog, ReadmeIsCurrent) {
  const rc::test::CommandResult r = rc::test::runShell(fmt::format(
      "RASTERCHECK='{}' '{}/scripts/gen-fixture-readme.sh' --check", RC_EXE, RC_SOURCE_DIR));
  EXPECT_EQ(r.code, 0) << r.out;
}

// --- Fixture design: the scenes show what their descriptions say, with the reference.

namespace {

Frame renderRef(const std::string& fixture) {
  return renderReference(catalogDir() / (fixture + ".json"));
}

nlohmann::json readJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

}  // namespace

// Painter's algorithm cannot resolve a cyclic overlap: the painter image differs from the
// z-buffer image at exactly one crossing (sticks 0 and 1, ids 1 and 2), with hard
// mismatches; no two sticks come near each other in depth (none intersects another).
TEST(FixtureDesign, CyclicOverlapDefeatsPainterAtOneCrossing) {
  const Frame zbuffer = renderRef("zbuffer/cyclic_overlap_zbuffer");
  const Frame painter = renderRef("visibility/cyclic_overlap_painter");
  const PairResult r =
      compareFrames(zbuffer, painter, zbuffer, tolerancesForFrames(zbuffer, painter));
  EXPECT_EQ(r.visibility.status, Status::Fail);
  EXPECT_GT(r.visibility.hard, 100u);
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  float min_gap = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < zbuffer.pixelCount(); ++i) {
    if (zbuffer.id[i] != painter.id[i]) pairs.insert({zbuffer.id[i], painter.id[i]});
    min_gap = std::min(min_gap, zbuffer.depth_gap[i]);
  }
  // Stick 0 (id 1) is over stick 1 (id 2); painter draws 1 after 0.
  EXPECT_EQ(pairs, (std::set<std::pair<std::uint32_t, std::uint32_t>>{{1, 2}}));
  // Where two sticks overlap they are at least ~0.1 apart in eye space: thousands of steps.
  EXPECT_GT(min_gap, 1000.0f);
}

// The A-buffer fixtures (tag oit): on oit_sorted_exact the sorted alpha pass is already
// exact, so the plain reference equals ref:abuffer bit for bit; on oit_cyclic they differ
// exactly where sticks 0 and 1 cross (found here from each stick rendered alone), where
// the exact answer shows stick 0 (id 1) over stick 1 and the draw order the reverse.
TEST(FixtureDesign, ABufferEqualsSortingWhereExactAndDiffersAtTheCyclicCrossing) {
  ReferenceOptions exact;
  exact.abuffer = true;
  const Scene sorted = loadScene(catalogDir() / "transparency" / "oit_sorted_exact.json");
  const Frame plain = rc::renderReference(sorted, ReferenceOptions{});
  const Frame abuffer = rc::renderReference(sorted, exact);
  EXPECT_EQ(plain.color, abuffer.color);
  EXPECT_EQ(plain.id, abuffer.id);
  EXPECT_EQ(abuffer.meta["abuffer"]["unsorted_pixels"].get<int>(), 0);
  EXPECT_GT(abuffer.meta["abuffer"]["blended_pixels"].get<int>(), 2000);

  const Scene cyclic = loadScene(catalogDir() / "transparency" / "oit_cyclic.json");
  ASSERT_EQ(cyclic.objects.size(), 4u);  // three sticks, then the wall
  auto alone = [&](std::size_t k) {
    Scene s = cyclic;
    s.objects = {cyclic.objects[k]};
    return rc::renderReference(s, ReferenceOptions{});
  };
  const Frame s0 = alone(0), s1 = alone(1), s2 = alone(2);
  const Frame p = rc::renderReference(cyclic, ReferenceOptions{});
  const Frame x = rc::renderReference(cyclic, exact);
  std::size_t crossing = 0;
  for (std::size_t i = 0; i < p.pixelCount(); ++i) {
    const bool expected_differ = s0.id[i] != 0 && s1.id[i] != 0;
    bool differ = p.id[i] != x.id[i];
    for (int c = 0; c < 4; ++c) differ = differ || p.color[4 * i + c] != x.color[4 * i + c];
    EXPECT_EQ(differ, expected_differ) << "pixel " << i % p.width << "," << i / p.width;
    if (!expected_differ || s2.id[i] != 0) continue;
    ++crossing;
    EXPECT_EQ(x.id[i], 1u);
    EXPECT_EQ(p.id[i], 2u);
  }
  EXPECT_GT(crossing, 100u);
  EXPECT_EQ(x.meta["abuffer"]["unsorted_pixels"].get<std::size_t>(), crossing);
}

namespace {

// The ladder of depth/zfight_*: 17 rows of 8 px (bottom first), separations 2^(row-4)
// d24 steps; fixtures/scenes/depth/zfight_ladder.py writes them.
constexpr int kLadderRows = 17;

// Pixels of the strips (ids above the plane's 1 and 2).
std::size_t stripPixels(const Frame& f) {
  std::size_t n = 0;
  for (std::uint32_t id : f.id) n += id > 2;
  return n;
}

}  // namespace

// Each format resolves what its precision allows, so the images differ: d16 < d24 < d32f
// at window z 0.1 (a float's ulp there is 1/8 of a d24 step), d16 < d24 at z 0.99975.
TEST(FixtureDesign, ZFightFormatsDiffer) {
  const std::size_t o16 = stripPixels(renderRef("depth/zfight_ortho_d16"));
  const std::size_t o24 = stripPixels(renderRef("depth/zfight_ortho_d24"));
  const std::size_t o32 = stripPixels(renderRef("depth/zfight_ortho_d32f"));
  const std::size_t p16 = stripPixels(renderRef("depth/zfight_perspective_d16"));
  const std::size_t p24 = stripPixels(renderRef("depth/zfight_perspective_d24"));
  // A row is 6 px x 128 = 768 strip pixels. d16 resolves rows >= 256 steps (5 rows),
  // d24 rows >= 1 step (13), d32f at z 0.1 rows >= 1/8 step (16); finer rows partly.
  const std::size_t row = 768;
  EXPECT_GE(o16, 5 * row);
  EXPECT_LT(o16, 7 * row);
  EXPECT_GE(o24, 13 * row);
  EXPECT_LT(o24, 15 * row);
  EXPECT_GE(o32, 16 * row);
  EXPECT_GE(p16, 5 * row);
  EXPECT_LT(p16, 7 * row);
  EXPECT_GE(p24, 13 * row);
  EXPECT_LT(p24, 15 * row);
}

// The ladder can fail: a renderer that shows the plane over every strip (as if the
// planes were swapped) fails hard on every row whose separation exceeds twice the depth
// fail tolerance, and is excused (ambiguous) on the rows below.
TEST(FixtureDesign, ZFightLadderCatchesSwappedPlanes) {
  for (const char* name :
       {"depth/zfight_ortho_d16", "depth/zfight_ortho_d24", "depth/zfight_ortho_d32f",
        "depth/zfight_perspective_d16", "depth/zfight_perspective_d24"}) {
    const Frame ref = renderRef(name);
    Frame swapped = ref;
    for (std::uint32_t& id : swapped.id) id = id > 2 ? 1 : id;
    const Tolerances tol = tolerancesForFrames(ref, swapped);
    const PairResult r = compareFrames(ref, swapped, ref, tol);
    // Separations in steps of the format: d16 steps are 256 d24 steps.
    const double per_d24 = tol.depth_format == DepthFormat::D16 ? 1.0 / 256.0 : 1.0;
    std::uint64_t sure_hard = 0, maybe_hard = 0;
    for (int row = 0; row < kLadderRows; ++row) {
      const double steps = std::ldexp(1.0, row - 4) * per_d24;
      if (steps > 4.0 * tol.depth.fail) sure_hard += 768;  // well clear of the allowance
      if (steps > 2.0 * tol.depth.fail) maybe_hard += 768;
    }
    EXPECT_EQ(r.visibility.status, Status::Fail) << name;
    EXPECT_GE(r.visibility.hard, sure_hard) << name;
    EXPECT_LE(r.visibility.hard, maybe_hard) << name;
    EXPECT_GT(r.visibility.ambiguous, 0u) << name;
  }
}

// The grazing checkerboards differ in texture filter and wrap only.
TEST(FixtureDesign, CheckerGrazingDiffersOnlyInFilterAndWrap) {
  std::optional<nlohmann::json> first;
  std::set<std::pair<std::string, std::string>> variants;
  for (const char* filter : {"nearest", "linear"}) {
    for (const char* wrap : {"repeat", "clamp"}) {
      auto doc =
          readJson(catalogDir() / fmt::format("texture/checker_grazing_{}_{}.json", filter, wrap));
      variants.insert({doc["state"]["texture_filter"].get<std::string>(),
                       doc["state"]["texture_wrap"].get<std::string>()});
      for (const char* key : {"name", "description"}) doc.erase(key);
      doc["state"].erase("texture_filter");
      doc["state"].erase("texture_wrap");
      if (!first) first = doc;
      EXPECT_EQ(doc, *first) << filter << " " << wrap;
    }
  }
  EXPECT_EQ(variants.size(), 4u);
}

// A backend that cannot start is told apart from one that fails on a fixture: the GL
// tests skip on the first and fail on the second.
TEST(Support, BackendThatCannotStartIsUnavailable) {
  const BackendRender r =
      renderWithBackend(catalogDir() / "coverage" / "triangle_fan.json", "gl:egl-device:99");
  EXPECT_FALSE(r.frame);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_TRUE(r.unavailable) << r.error;
}
