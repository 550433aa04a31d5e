// One scene, two renderers, one comparison, in this process: compareFrames(renderReference(s),
// renderGl(s)) must give exactly what `rastercheck render` twice and `rastercheck compare`
// give, on a fixture whose depth format (d16), colour format (rgba8) and linearly filtered
// texture all differ from the defaults the comparator falls back to when a frame does not
// say (d24, rgba32f, untextured). The frames carry those facts themselves (Frame::drawn).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/command.h"
#include "compare/compare.h"
#include "compare/report.h"
#include "fixtures/loader.h"
#include "gl_test_util.h"
#include "reference/reference_renderer.h"

namespace rc {
namespace {
namespace fs = std::filesystem;
using gltest::GlTest;
using gltest::specText;

const fs::path kFixture = fs::path(RC_SOURCE_DIR) / "tests/gl/data/d16_rgba8_textured.json";

// The parts of a report.json row that are the comparison's answer: everything but names,
// paths, driver strings, the scales of its pictures and timings, which the CLI adds.
nlohmann::json verdictOf(nlohmann::json row) {
  for (const char* key : {"fixture", "fixture_file", "expected", "actual", "state", "tags",
                          "stacks", "images", "heat_scales", "seconds", "known"})
    row.erase(key);
  return row;
}

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

class GlInProcess : public GlTest {};

TEST_F(GlInProcess, CompareFramesGivesTheVerdictOfTheCommandLine) {
  const Scene scene = loadScene(kFixture);
  const Frame ref = renderReference(scene);
  const Frame gl = renderGl(scene, gltest::spec());
  // Set by each renderer from the scene, no caller stamping them.
  for (const Frame* f : {&ref, &gl}) {
    EXPECT_EQ(f->drawn.depth_format, DepthFormat::D16);
    EXPECT_EQ(f->drawn.color_format, ColorFormat::RGBA8);
    EXPECT_EQ(f->drawn.texture_filter, TextureFilter::Linear);
    EXPECT_TRUE(f->drawn.textured);
  }
  const PairResult in_process = compareFrames(ref, gl);
  EXPECT_EQ(in_process.tolerances.depth_format, DepthFormat::D16);
  EXPECT_EQ(in_process.tolerances.color_format, ColorFormat::RGBA8);
  EXPECT_GT(in_process.tolerances.texture_weight_error, 0.0);  // the linear filtering allowance
  // The fixture's own "tolerance" block travels with the frames (the second layer).
  EXPECT_EQ(in_process.tolerances.shading.warn, 0.25);
  EXPECT_EQ(in_process.tolerances.shading.fail, 3.0);
  EXPECT_EQ(in_process.tolerances.depth.warn, 1.0);
  EXPECT_EQ(in_process.tolerances.depth.fail, 4.0);

  const fs::path dir =
      fs::temp_directory_path() /
      ("rc_in_process_" + std::to_string(::getpid()) + "_" +
       std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::remove_all(dir);
  const std::string exe = RC_EXE;
  for (const auto& [backend, out] :
       {std::pair{std::string("ref"), dir / "ref"}, std::pair{specText(), dir / "gl"}}) {
    const test::CommandResult r = test::runShell(exe + " render " + quoted(kFixture) +
                                                 " --backend " + backend + " --out " + quoted(out));
    ASSERT_EQ(r.code, 0) << backend << ": " << r.out;
  }
  const test::CommandResult r =
      test::runShell(exe + " compare " + quoted(dir / "ref") + " " + quoted(dir / "gl") +
                     " --out " + quoted(dir / "cmp"));
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.out;
  std::ifstream in(dir / "cmp" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  ASSERT_EQ(report["results"].size(), 1u);
  const nlohmann::json cli = verdictOf(report["results"][0]);
  // Through report.json's JSON writer on both sides, so that every number is compared.
  const nlohmann::json ours = verdictOf(toJson(in_process, dir / "cmp"));
  EXPECT_EQ(ours, cli) << "in process:\n" << ours.dump(1) << "\ncommand line:\n" << cli.dump(1);
  EXPECT_EQ(r.code, in_process.status == Status::Fail ? 1 : 0) << r.out;

  // The test can fail: frames that do not say how they were drawn are compared as d24
  // rgba32f untextured, and that answer differs (d16 steps are 256 d24 steps).
  Frame ref_unsaid = ref, gl_unsaid = gl;
  ref_unsaid.drawn = {};
  gl_unsaid.drawn = {};
  EXPECT_NE(verdictOf(toJson(compareFrames(ref_unsaid, gl_unsaid), dir / "cmp")), cli);
  // ... and without the fixture's block only the formats' defaults apply.
  Frame ref_default = ref, gl_default = gl;
  ref_default.drawn.tolerance.reset();
  gl_default.drawn.tolerance.reset();
  EXPECT_NE(compareFrames(ref_default, gl_default).tolerances.shading.warn, 0.25);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rc
