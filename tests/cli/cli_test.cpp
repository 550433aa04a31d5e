// The rastercheck command as a user meets it: help and version, exit codes 0/1/2/3 of
// render, compare and run, one-line errors that name the file and JSON path, no output
// left after a failure, the closing summary and report path.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/report_support.h"
#include "compare/pair_images.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/multisample.h"
#include "tests/support/command.h"

namespace fs = std::filesystem;

namespace {

using Result = rc::test::CommandResult;  // stdout and stderr together in `out`

Result run(const std::string& args, const std::string& env = "") {
  return rc::test::runShell(env + " " RC_EXE " " + args);
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string catalog(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/fixtures/scenes/" + rel;
}

int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace

TEST(Cli, HelpAndVersion) {
  Result help = run("--help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("render"), std::string::npos);
  EXPECT_NE(help.out.find("Exit codes"), std::string::npos);
  Result version = run("--version");
  EXPECT_EQ(version.code, 0);
  EXPECT_NE(version.out.find("rastercheck 0."), std::string::npos);
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(run("render").code, 2);
}

TEST(Cli, RenderReferenceWritesTheFrameDirectory) {
  const fs::path out = scratch("render") / "frame";
  Result r = run("render " + catalog("coverage/triangle_fan.json") + " --backend ref --out " +
                 out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const rc::Frame f = rc::readFrameDir(out);
  EXPECT_EQ(f.width, 128);
  EXPECT_EQ(f.height, 128);
  EXPECT_TRUE(f.hasUncertainty());
  EXPECT_EQ(f.meta["backend"], "ref");
  EXPECT_EQ(f.meta["fixture"], "coverage/triangle_fan");
  EXPECT_EQ(f.meta["subpixel_bits"], 8);
  EXPECT_TRUE(fs::exists(out / "color.png"));
  // frame_digest covers every plane (scripts/same-bits.sh compares it between runs): the
  // digest of the frame read back, and another for a frame one depth value away.
  ASSERT_TRUE(f.meta.contains("frame_digest"));
  EXPECT_EQ(f.meta["frame_digest"], rc::frameDigest(f));
  rc::Frame moved = f;
  moved.depth[moved.depth.size() / 2] += 1e-3f;
  EXPECT_NE(rc::frameDigest(moved), rc::frameDigest(f));
}

// A multi-pass fixture with --all-passes: each pass before the frame pass as a frame folder
// of its own, OUT/passes/K-TARGET, at the target's size (the map a depth frame).
TEST(Cli, RenderAllPassesWritesEveryTarget) {
  const fs::path out = scratch("passes") / "frame";
  Result r = run("render " + catalog("multipass/mirror_quad.json") + " --all-passes --out " +
                 out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("pass 0 (mirror 128x128)"), std::string::npos) << r.out;
  const rc::Frame f = rc::readFrameDir(out);
  EXPECT_EQ(f.width, 200);
  const rc::Frame mirror = rc::readFrameDir(out / "passes" / "0-mirror");
  EXPECT_EQ(mirror.width, 128);
  EXPECT_EQ(mirror.height, 128);
  EXPECT_EQ(mirror.meta["pass"]["target"], "mirror");
  // Without the flag only the frame is written.
  const fs::path plain = scratch("passes_plain") / "frame";
  ASSERT_EQ(
      run("render " + catalog("multipass/mirror_quad.json") + " --out " + plain.string()).code, 0);
  EXPECT_FALSE(fs::exists(plain / "passes"));
}

TEST(Cli, UnknownBackendExitsTwoBeforeWriting) {
  const fs::path out = scratch("badspec") / "frame";
  Result r = run("render " + catalog("coverage/triangle_fan.json") + " --backend vulkan --out " +
                 out.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("vulkan"), std::string::npos);
  EXPECT_EQ(lineCount(r.out), 1) << r.out;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run("render x.json --backend ref:subpixel=99 --out " + out.string()).code, 2);
}

TEST(Cli, BadFixtureExitsTwoWithFileAndJsonPath) {
  const fs::path dir = scratch("badfix");
  const fs::path scene = dir / "bad.json";
  std::ofstream(scene) << R"({"format": "rastercheck-scene/1", "image": {"width": 8, "height": 8},
    "camera": {"eye": [0, 0, 5]}, "objects": [{"mesh": {"file": "nowhere.obj"}}]})";
  const fs::path out = dir / "frame";
  Result r = run("render " + scene.string() + " --backend ref --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(lineCount(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("bad.json"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("objects[0].mesh.file"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, MissingSceneFileExitsTwo) {
  Result r = run("render /nonexistent/scene.json --backend ref --out /tmp/rc_cli_never");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("/nonexistent/scene.json"), std::string::npos);
  EXPECT_FALSE(fs::exists("/tmp/rc_cli_never"));
}

TEST(Cli, EglDeviceWithoutGpuExitsThree) {
  const fs::path out = scratch("egldev") / "frame";
  Result r = run("render " + catalog("coverage/triangle_fan.json") +
                 " --backend gl:egl-device --out " + out.string());
  // No GPU is attached to the machines this suite runs on; where one is, it renders.
  if (r.code == 0) GTEST_SKIP() << "a GPU is present: " << r.out;
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("device"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, ListShowsTheCatalog) {
  Result r = run("list " + catalog(""));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("shading/blinn_phong_sphere"), std::string::npos);
  EXPECT_NE(r.out.find("coverage/triangle_fan"), std::string::npos);
}

// ---- compare and run ----

namespace {

std::string crafted(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/tests/compare/data/" + rel;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int occurrences(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Renders `fixture` with `backend` into dir/name and returns the folder.
fs::path renderTo(const fs::path& dir, const std::string& name, const std::string& fixture,
                  const std::string& backend) {
  fs::path out = dir / name;
  const Result r = run("render " + fixture + " --backend " + backend + " --out " + out.string());
  EXPECT_EQ(r.code, 0) << r.out;
  return out;
}

bool hasStagingLeftovers(const fs::path& dir) {
  if (!fs::exists(dir)) return false;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find("staging") != std::string::npos ||
        e.path().filename().string().find(".tmp-") != std::string::npos)
      return true;
  return false;
}

void expectReportFiles(const fs::path& out) {
  for (const char* f : {"report.json", "junit.xml", "report.html"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  EXPECT_FALSE(hasStagingLeftovers(out));
}

}  // namespace

TEST(CliCompare, IdenticalFramesPassWithTheSummaryAndReportPath) {
  const fs::path dir = scratch("cmp_pass");
  const std::string fixture = catalog("coverage/triangle_fan.json");
  const fs::path a = renderTo(dir, "a", fixture, "ref");
  const fs::path b = renderTo(dir, "b", fixture, "ref:subpixel=8");
  const fs::path out = dir / "report";
  const Result r = run("compare " + a.string() + " " + b.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("report: " + fs::absolute(out).string() + "/report.html"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("coverage/triangle_fan"), std::string::npos) << r.out;  // the table
  EXPECT_NE(r.out.find("ref:subpixel=8"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 pairs: 1 pass"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.substr(r.out.size() - 5), "PASS\n") << r.out;
  expectReportFiles(out);
  const fs::path pair = out / "pairs" / "coverage_triangle_fan" / "ref_vs_ref_subpixel_8";
  EXPECT_TRUE(fs::is_regular_file(pair / "visibility.png"));
  // A passing pair gets no diff.exr (75 MB at 1080p) unless asked for.
  EXPECT_FALSE(fs::exists(pair / "diff.exr"));
  EXPECT_EQ(readFile(out / "report.json").find("diff_exr"), std::string::npos);
  const Result forced =
      run("compare " + a.string() + " " + b.string() + " --diff-exr --out " + out.string());
  EXPECT_EQ(forced.code, 0) << forced.out;
  EXPECT_TRUE(fs::is_regular_file(pair / "diff.exr"));
}

TEST(CliCompare, AFailingPairExitsOne) {
  const fs::path dir = scratch("cmp_fail");
  const std::string fixture = crafted("interpenetrating.json");
  const fs::path a = renderTo(dir, "z", fixture, "ref");
  const fs::path b = renderTo(dir, "p", fixture, "ref:painter");
  const Result r =
      run("compare " + a.string() + " " + b.string() + " --out " + (dir / "report").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("FAIL compare-tests/interpenetrating ref vs ref:painter: visibility fail"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.substr(r.out.size() - 8), "FAILURE\n") << r.out;
  expectReportFiles(dir / "report");
}

// LDR-FLIP is opt-in (with it a compare takes about twice idiff's time): a plain
// compare has no flip block and no flip_heat.png, --flip adds both, --flip-threshold
// implies it; CIEDE2000 is in every compared pair.
TEST(CliCompare, FlipIsOptInAndCiede2000AlwaysThere) {
  const fs::path dir = scratch("cmp_flip");
  const std::string fixture = crafted("interpenetrating.json");
  const fs::path a = renderTo(dir, "z", fixture, "ref");
  const fs::path b = renderTo(dir, "p", fixture, "ref:painter");
  auto compare = [&](const std::string& extra) {
    const fs::path out = dir / "report";
    const Result r =
        run("compare " + a.string() + " " + b.string() + " --out " + out.string() + extra);
    EXPECT_EQ(r.code, 1) << r.out;
    bool heat = false;
    for (const auto& e : fs::recursive_directory_iterator(out))
      heat = heat || e.path().filename() == "flip_heat.png";
    nlohmann::json row = nlohmann::json::parse(readFile(out / "report.json")).at("results").at(0);
    EXPECT_EQ(row.contains("flip"), heat) << extra;
    EXPECT_TRUE(row.contains("ciede2000")) << extra;
    EXPECT_GT(row.at("ciede2000").at("differing"), 0) << extra;
    return row;
  };
  EXPECT_FALSE(compare("").contains("flip"));
  const nlohmann::json asked = compare(" --flip");
  ASSERT_TRUE(asked.contains("flip"));
  EXPECT_GT(asked.at("flip").at("mean"), 0.0);
  EXPECT_TRUE(asked.at("flip").at("threshold").is_null());
  const nlohmann::json threshold = compare(" --flip-threshold 0.5");
  ASSERT_TRUE(threshold.contains("flip"));
  EXPECT_EQ(threshold.at("flip").at("threshold"), 0.5);
}

TEST(CliCompare, BadInputExitsTwoWithOneLineAndWritesNothing) {
  const fs::path dir = scratch("cmp_bad");
  const std::string fixture = catalog("coverage/triangle_fan.json");
  const fs::path a = renderTo(dir, "a", fixture, "ref");
  const fs::path out = dir / "report";
  auto expectTwo = [&](const std::string& args, const std::string& mention) {
    const Result r = run("compare " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_EQ(lineCount(r.out), 1) << r.out;
    EXPECT_NE(r.out.find(mention), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("internal error"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out)) << args;
  };
  expectTwo(a.string() + " " + (dir / "nowhere").string() + " --out " + out.string(), "nowhere");
  expectTwo(a.string() + " " + a.string() + " --out " + out.string() + " --tolerance depth.x=1",
            "depth.x");
  expectTwo(a.string() + " " + a.string() + " --out " + out.string() +
                " --tolerance depth.warn=8 --tolerance depth.fail=4",
            "warn");
  // Frames of another size.
  const fs::path big = renderTo(dir, "big", catalog("shading/teapot.json"), "ref");
  expectTwo(a.string() + " " + big.string() + " --out " + out.string(), "differ in size");
  // --out names a file: refused, and the file is left alone.
  std::ofstream(dir / "file") << "keep";
  const Result r =
      run("compare " + a.string() + " " + a.string() + " --out " + (dir / "file").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(readFile(dir / "file"), "keep");
}

TEST(CliRun, ExitCodesZeroOneTwoThree) {
  const fs::path dir = scratch("run_codes");
  // 0: the reference against itself at the same precision.
  Result r = run("run " + catalog("coverage/triangle_fan.json") +
                 " --backends ref:subpixel=8 --out " + (dir / "pass").string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("report: " + fs::absolute(dir / "pass").string() + "/report.html"),
            std::string::npos)
      << r.out;
  expectReportFiles(dir / "pass");
  // Frames and pair images only for pairs that do not pass, unless --keep-frames.
  EXPECT_FALSE(fs::exists(dir / "pass" / "frames"));
  EXPECT_FALSE(fs::exists(dir / "pass" / "pairs"));
  r = run("run " + catalog("coverage/triangle_fan.json") +
          " --backends ref:subpixel=8 --keep-frames --out " + (dir / "kept").string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::is_regular_file(dir / "kept" / "frames" / "coverage__triangle_fan" /
                                  "ref_subpixel_8" / "frame.exr"));
  EXPECT_TRUE(fs::is_regular_file(dir / "kept" / "pairs" / "coverage_triangle_fan" /
                                  "ref_vs_ref_subpixel_8" / "diff.exr"));

  // 1: painter's order cannot draw interpenetrating quads.
  r = run("run " + crafted("interpenetrating.json") + " --backends ref:painter --out " +
          (dir / "fail").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("FAIL compare-tests/interpenetrating"), std::string::npos) << r.out;
  // FLIP only with --flip (CliCompare.FlipIsOptInAndCiede2000AlwaysThere); CIEDE2000 always.
  const nlohmann::json plain = nlohmann::json::parse(readFile(dir / "fail" / "report.json"));
  EXPECT_FALSE(plain.at("results").at(0).contains("flip"));
  EXPECT_TRUE(plain.at("results").at(0).contains("ciede2000"));
  r = run("run " + crafted("interpenetrating.json") + " --backends ref:painter --flip --out " +
          (dir / "fail").string());
  EXPECT_EQ(r.code, 1) << r.out;
  const nlohmann::json flip = nlohmann::json::parse(readFile(dir / "fail" / "report.json"));
  EXPECT_GT(flip.at("results").at(0).at("flip").at("mean"), 0.0);

  // 3: a backend that cannot start; the report is still written, one error row, and the
  // reason names the backend once.
  r = run("run " + catalog("coverage/triangle_fan.json") + " --backends gl:egl-device:7 --out " +
          (dir / "error").string());
  if (r.code == 0) GTEST_SKIP() << "an EGL device 7 exists here";
  EXPECT_EQ(r.code, 3) << r.out;
  expectReportFiles(dir / "error");
  const std::string error_line = r.out.substr(0, r.out.find('\n'));
  EXPECT_EQ(error_line.rfind("ERROR coverage/triangle_fan ref vs gl:egl-device:7: ", 0), 0u)
      << error_line;
  EXPECT_EQ(occurrences(error_line, "gl:egl-device:7"), 1) << error_line;
  EXPECT_EQ(occurrences(error_line, "coverage/triangle_fan"), 1) << error_line;
  const std::string json = readFile(dir / "error" / "report.json");
  EXPECT_NE(json.find("\"status\": \"error\""), std::string::npos);
}

TEST(CliRun, BadInputExitsTwoBeforeRenderingAndWritesNothing) {
  const fs::path dir = scratch("run_bad");
  const fs::path out = dir / "out";
  auto expectTwo = [&](const std::string& args, const std::string& mention) {
    const Result r = run("run " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_EQ(lineCount(r.out), 1) << r.out;
    EXPECT_NE(r.out.find(mention), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("internal error"), std::string::npos) << r.out;
  };
  const fs::path bad = dir / "bad.json";
  std::ofstream(bad) << R"({"format": "rastercheck-scene/1", "image": {"width": 8, "height": 8},
    "camera": {"eye": [0, 0, 5]}, "objects": [{"mesh": {"generator": "cube"}}],
    "state": {"shading": "glossy"}})";
  expectTwo(bad.string() + " --backends ref:painter --out " + out.string(), "state.shading");
  EXPECT_FALSE(fs::exists(out));
  expectTwo(catalog("coverage/triangle_fan.json") + " --backends vulkan --out " + out.string(),
            "vulkan");
  EXPECT_FALSE(fs::exists(out));
  expectTwo(catalog("coverage/triangle_fan.json") +
                " --backends ref:painter --tolerance shading.warn=2 --tolerance shading.fail=1"
                " --out " +
                out.string(),
            "shading");
  EXPECT_FALSE(fs::exists(out));
  std::ofstream(dir / "file") << "keep";
  expectTwo(catalog("coverage/triangle_fan.json") + " --backends ref:painter --out " +
                (dir / "file").string(),
            "file");
  EXPECT_EQ(readFile(dir / "file"), "keep");
}

TEST(CliRun, ARunReplacesWhatAnEarlierRunLeftAndNothingElse) {
  const fs::path dir = scratch("run_replace");
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "mine";
  Result r = run("run " + catalog("coverage/triangle_fan.json") +
                 " --backends ref:subpixel=8 --keep-frames --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::is_directory(out / "pairs" / "coverage_triangle_fan"));
  const std::string first_report = readFile(out / "report.json");

  // A run that fails on bad input leaves the earlier outputs as they were.
  r = run("run " + catalog("coverage/jittered_grid.json") + " --backends vulkan --out " +
          out.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(readFile(out / "report.json"), first_report);

  // Another catalog: the first run's pairs and frames are gone, the user's file stays.
  r = run("run " + catalog("coverage/jittered_grid.json") +
          " --backends ref:subpixel=8 --keep-frames --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(fs::exists(out / "pairs" / "coverage_triangle_fan"));
  EXPECT_FALSE(fs::exists(out / "frames" / "coverage__triangle_fan"));
  EXPECT_TRUE(fs::is_directory(out / "pairs" / "coverage_jittered_grid"));
  EXPECT_EQ(readFile(out / "notes.txt"), "mine");
  EXPECT_EQ(readFile(out / "report.json").find("triangle_fan"), std::string::npos);
  EXPECT_FALSE(hasStagingLeftovers(out));
}

TEST(CliRun, SummaryTableListsEveryFixtureAndBackend) {
  const fs::path dir = scratch("run_table");
  const Result r = run("run " + catalog("coverage") +
                       " --backends ref:subpixel=8,ref:subpixel=4 --out " + (dir / "out").string());
  EXPECT_LE(r.code, 1) << r.out;
  const std::size_t header = r.out.find("fixture ");
  ASSERT_NE(header, std::string::npos) << r.out;
  const std::string head_line = r.out.substr(header, r.out.find('\n', header) - header);
  EXPECT_NE(head_line.find("ref:subpixel=8"), std::string::npos) << head_line;
  EXPECT_NE(head_line.find("ref:subpixel=4"), std::string::npos) << head_line;
  for (const char* f :
       {"coverage/jittered_grid", "coverage/slivers_and_centres", "coverage/triangle_fan"})
    EXPECT_NE(r.out.find(f, header), std::string::npos) << f << "\n" << r.out;
  EXPECT_NE(r.out.find("v: hard visibility px"), std::string::npos);
}

TEST(CliCompare, PicturesAreReusedOnlyWhenTheyShowTheComparedFrames) {
  const fs::path dir = scratch("cmp_pictures");
  const std::string fixture = catalog("coverage/triangle_fan.json");
  const fs::path a = renderTo(dir, "a", fixture, "ref");
  const fs::path b = renderTo(dir, "b", fixture, "ref:subpixel=8");
  // b's frame.exr changed after `render` (a fault injected into the colour only):
  // frame.json still has the old digest, so b's color.png no longer shows the frame.
  rc::Frame changed = rc::readFrameDir(b);
  for (std::size_t i = 0; i < changed.pixelCount(); ++i)
    if (changed.id[i] != 0) changed.color[i * 4] += 0.25f;
  rc::writeFrameExr(changed, b / "frame.exr");
  const fs::path out = dir / "report";
  const Result r = run("compare " + a.string() + " " + b.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 1) << r.out;
  const fs::path pair = out / "pairs" / "coverage_triangle_fan" / "ref_vs_ref_subpixel_8";
  EXPECT_TRUE(fs::equivalent(pair / "expected.png", a / "color.png"));  // linked
  EXPECT_FALSE(fs::equivalent(pair / "actual.png", b / "color.png"));   // encoded anew
  EXPECT_NE(readFile(pair / "actual.png"), readFile(b / "color.png"));
}

TEST(SummaryTable, CompactForBigCatalogsListsOnlyWhatDidNotPass) {
  rc::Report report;
  for (int f = 0; f < 6; ++f) {
    for (const char* backend : {"gl:a", "gl:b"}) {
      rc::PairResult r;
      r.fixture = "set/fixture" + std::to_string(f);
      r.expected = "ref";
      r.actual = backend;
      if (f == 3 && std::string(backend) == "gl:b") {
        r.status = rc::Status::Fail;
        r.visibility.hard = 12;
        r.depth.max_steps = 40;
        r.shading.max_abs = 2.5;
      }
      report.results.push_back(r);
    }
  }
  report.results.push_back(rc::errorResult("set/fixture5", "ref", "gl:b", "no driver"));
  const std::string full = rc::summaryTable(report, 40);
  for (int f = 0; f < 6; ++f)
    EXPECT_NE(full.find("set/fixture" + std::to_string(f)), std::string::npos) << full;
  EXPECT_NE(full.find("FAIL v12 d40 s2.5"), std::string::npos) << full;
  const std::string compact = rc::summaryTable(report, 4);
  EXPECT_EQ(compact.find("set/fixture0"), std::string::npos) << compact;
  EXPECT_NE(compact.find("set/fixture3"), std::string::npos) << compact;
  EXPECT_NE(compact.find("set/fixture5"), std::string::npos) << compact;  // the error row
  EXPECT_NE(compact.find("ERROR"), std::string::npos) << compact;
  EXPECT_NE(compact.find("(all 6)"), std::string::npos) << compact;
  EXPECT_NE(compact.find("6 pass"), std::string::npos) << compact;  // gl:a
  EXPECT_NE(compact.find("4 pass, 1 fail, 1 error"), std::string::npos) << compact;
  EXPECT_NE(compact.find("(4 fixtures that pass on every backend not listed)"), std::string::npos)
      << compact;
}

TEST(CliCompare, TheFixturesToleranceBlockAppliesAndTheCommandLineWins) {
  const fs::path dir = scratch("cmp_tolerance");
  // The interpenetrating quads with a visibility tolerance that forgives painter's order.
  std::string text = readFile(crafted("interpenetrating.json"));
  text.replace(text.rfind('}'), 1,
               R"(, "tolerance": {"visibility": {"warn": 0, "fail": 100000}}})");
  const fs::path fixture = dir / "forgiving.json";
  std::ofstream(fixture) << text;
  const fs::path a = renderTo(dir, "z", fixture.string(), "ref");
  const fs::path b = renderTo(dir, "p", fixture.string(), "ref:painter");
  // render recorded the block in frame.json: compare applies it without the fixture.
  fs::remove(fixture);
  Result r =
      run("compare " + a.string() + " " + b.string() + " --out " + (dir / "report").string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.substr(r.out.size() - 8), "WARNING\n") << r.out;
  r = run("compare " + a.string() + " " + b.string() + " --out " + (dir / "report").string() +
          " --tolerance visibility.fail=10");
  EXPECT_EQ(r.code, 1) << r.out;
}

namespace {

// `run` compares a multisampled reference at the positions the driver reports: a GL frame
// whose frame.json names other positions makes the reference render again there (and
// keep its frame.json keys); equal positions, or a single-sample frame, change nothing.
TEST(ResampleReference, RendersAgainAtTheDriversPositions) {
  const std::filesystem::path fixture =
      std::filesystem::path(RC_SOURCE_DIR) / "fixtures/scenes/msaa/edge_slopes.json";
  const rc::Frame original = rc::renderReference(rc::loadScene(fixture));
  rc::Frame ref = original;
  ref.meta["backend"] = "ref";
  rc::Frame gl = original;
  gl.meta["backend"] = "gl:fake";
  rc::resampleReference(ref, gl, fixture, {});  // same (standard) positions
  EXPECT_EQ(ref.sample_id, original.sample_id);
  EXPECT_EQ(ref.meta["multisample"]["positions_source"], "standard");

  nlohmann::json mirrored = nlohmann::json::array();
  for (const glm::dvec2& p : rc::standardSamplePositions(4)) mirrored.push_back({p.x, 1.0 - p.y});
  gl.meta["multisample"]["positions"] = mirrored;
  rc::resampleReference(ref, gl, fixture, {});
  EXPECT_NE(ref.sample_id, original.sample_id);
  EXPECT_EQ(ref.meta["multisample"]["positions"], mirrored);
  EXPECT_EQ(ref.meta["multisample"]["positions_from"], "gl:fake");
  EXPECT_EQ(ref.meta["backend"], "ref");
}

}  // namespace

namespace {

std::vector<fs::path> cachedImports(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".rcmesh") out.push_back(e.path());
  return out;
}

std::string fileText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

nlohmann::json frameMeta(const fs::path& dir) {
  std::ifstream in(dir / "frame.json");
  return nlohmann::json::parse(in);
}

}  // namespace

// Mesh imports shared between processes (fixtures/mesh_import.h, SharedImportCache, which
// `run` sets up for its workers): with RASTERCHECK_MESH_CACHE naming a folder, a render
// leaves each mesh file's import there, and a later process reads it back instead of
// starting the importer. Shown by swapping the cube's cached stream for the spider's (the
// cube's key line kept): the next render of the cube scene then draws the spider. Without
// the variable nothing is shared and the cube is the cube again.
TEST(Cli, MeshImportsAreSharedThroughTheCacheFolder) {
  const fs::path dir = scratch("mesh_cache");
  const fs::path cache = dir / "cache";
  fs::create_directories(cache);
  const std::string env = "RASTERCHECK_MESH_CACHE=" + cache.string();
  ASSERT_EQ(run("render " + catalog("real-mesh/ply_mesh.json") + " --backend ref --out " +
                    (dir / "cube").string(),
                env)
                .code,
            0);
  const std::vector<fs::path> after_cube = cachedImports(cache);
  ASSERT_EQ(after_cube.size(), 1u);
  ASSERT_EQ(run("render " + catalog("real-mesh/stl_mesh.json") + " --backend ref --out " +
                    (dir / "spider").string(),
                env)
                .code,
            0);
  std::vector<fs::path> after_spider = cachedImports(cache);
  ASSERT_EQ(after_spider.size(), 2u);
  const fs::path& cube_file = after_cube.front();
  const fs::path spider_file = after_spider[0] == cube_file ? after_spider[1] : after_spider[0];
  const std::string cube_text = fileText(cube_file);
  const std::string spider_text = fileText(spider_file);
  ASSERT_EQ(cube_text.rfind("rastercheck mesh import|", 0), 0u);
  const std::string swapped = cube_text.substr(0, cube_text.find('\n') + 1) +
                              spider_text.substr(spider_text.find('\n') + 1);
  std::ofstream(cube_file, std::ios::binary | std::ios::trunc) << swapped;

  ASSERT_EQ(run("render " + catalog("real-mesh/ply_mesh.json") + " --backend ref --out " +
                    (dir / "swapped").string(),
                env)
                .code,
            0);
  ASSERT_EQ(run("render " + catalog("real-mesh/ply_mesh.json") + " --backend ref --out " +
                (dir / "alone").string())
                .code,
            0);
  const auto triangles = [&](const char* name) {
    return frameMeta(dir / name).at("triangles_rasterized").get<std::uint64_t>();
  };
  EXPECT_NE(triangles("swapped"), triangles("cube")) << "the shared stream was not read";
  EXPECT_GT(triangles("swapped"), 100u);  // the spider's, not the cube's 12
  EXPECT_EQ(triangles("alone"), triangles("cube"));
  fs::remove_all(dir);
}

// `run` loads its fixtures on every core, but reports the first bad one in file order, as
// one by one: of two broken fixtures among good ones, the first (by name) is named, every
// time, and nothing is written.
TEST(Cli, RunNamesTheFirstBadFixtureInOrder) {
  const fs::path dir = scratch("first_bad");
  const fs::path in = dir / "in";
  fs::create_directories(in);
  for (int i = 0; i < 6; ++i)
    fs::copy_file(catalog("coverage/triangle_fan.json"),
                  in / ("a" + std::to_string(i) + "_good.json"));
  std::ofstream(in / "b_bad.json") << "{\"format\": \"rastercheck-scene/1\", \"width\": -3}";
  std::ofstream(in / "c_bad.json") << "{\"format\": \"rastercheck-scene/1\", \"zzz\": 1}";
  for (int attempt = 0; attempt < 5; ++attempt) {
    const Result r =
        run("run " + in.string() + " --backends ref:painter --out " + (dir / "out").string());
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("b_bad.json"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("c_bad.json"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
  fs::remove_all(dir);
}
