// `run`'s long-lived workers against drivers that misbehave (RASTERCHECK_GL_FAULT hang and
// crash, gl_backend/gl_testing.h): the render that hangs or crashes becomes one error row
// naming the timeout or the signal, its worker is replaced, and the fixtures before and
// after it are rendered and compared as usual. Also the faults themselves through
// `render`, so that the run tests cannot pass by the faults doing nothing. Then `run --retries`
// and deqp-runner's files (RunFlakes, below).

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/worker_pool.h"
#include "tests/support/command.h"
#include "tests/support/random_fixtures.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Result = rc::test::CommandResult;

Result run(const std::string& args, const std::string& env = "") {
  return rc::test::runShell(env + " " RC_EXE " " + args);
}

std::string catalog(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/fixtures/scenes/" + rel;
}

fs::path scratch(const std::string& name) {
  fs::path p =
      fs::temp_directory_path() / ("rc_gl_workers_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

// A pool of this build's workers, their logs in DIR/workers.
rc::WorkerPool::Options poolOptions(const fs::path& dir) {
  rc::WorkerPool::Options options;
  options.log_dir = dir / "workers";
  options.program = RC_EXE;
  return options;
}

// Three fixtures llvmpipe renders within tolerance; the middle one gets the fault.
const std::string kFixtures = catalog("coverage/triangle_fan.json") + " " +
                              catalog("zbuffer/interpenetrating_ab.json") + " " +
                              catalog("shading/sphere_gouraud_low.json");
constexpr const char* kVictim = "zbuffer/interpenetrating_ab";

// Whether llvmpipe starts here at all (else the tests below have nothing to show).
bool llvmpipeRuns(const fs::path& dir) {
  const Result r = run("render " + catalog("coverage/triangle_fan.json") +
                       " --backend gl:egl:llvmpipe --out " + (dir / "probe").string());
  if (r.code == 0) return true;
  const char* req = std::getenv("RASTERCHECK_REQUIRE_GL");
  if (req != nullptr && std::string(req) == "1")
    ADD_FAILURE() << "RASTERCHECK_REQUIRE_GL=1 but llvmpipe does not start: " << r.out;
  return false;
}

// The run's rows by fixture; every other fixture passes or warns and the victim's row is
// an error whose message contains `why`.
void expectOneErrorRow(const fs::path& out, const std::string& why) {
  const json report = json::parse(std::ifstream(out / "report.json"));
  ASSERT_EQ(report["results"].size(), 3u) << report.dump(1);
  for (const json& row : report["results"]) {
    SCOPED_TRACE(row["fixture"].get<std::string>());
    if (row["fixture"] == kVictim) {
      EXPECT_EQ(row["status"], "error");
      EXPECT_NE(row["error"].get<std::string>().find(why), std::string::npos) << row["error"];
    } else {
      EXPECT_TRUE(row["status"] == "pass" || row["status"] == "warn") << row.dump();
    }
  }
  EXPECT_EQ(report["exit_code"], 3);
}

TEST(GlWorkers, AHangingDriverCostsOneRowAndTheRunGoesOn) {
  const fs::path dir = scratch("hang");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  const auto start = std::chrono::steady_clock::now();
  // 8 s, not less: the watchdog also times the fixtures that do not hang, and at load ~17
  // on two cores a llvmpipe worker's start plus one render took over 3 s (two runs failed).
  const Result r =
      run("run " + kFixtures + " --backends gl:egl:llvmpipe --no-variants --timeout 8 " + "--out " +
              (dir / "out").string(),
          std::string("RASTERCHECK_GL_FAULT=hang=") + kVictim);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.code, 3) << r.out;
  expectOneErrorRow(dir / "out", "timed out after 8 s");
  EXPECT_LT(seconds, 60.0) << "the watchdog let the run wait";
  // What the worker printed during the render it was killed in is kept beside the frames
  // (whichever fixtures the same worker rendered before it: the fault announces itself).
  const fs::path log =
      dir / "out" / "frames" / "zbuffer__interpenetrating_ab" / "gl_egl_llvmpipe.log";
  ASSERT_TRUE(fs::exists(log));
  std::stringstream printed;
  printed << std::ifstream(log).rdbuf();
  EXPECT_NE(printed.str().find("the draw of"), std::string::npos) << printed.str();
  fs::remove_all(dir);
}

TEST(GlWorkers, ACrashingDriverCostsOneRowAndTheRunGoesOn) {
  const fs::path dir = scratch("crash");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  const Result r = run("run " + kFixtures + " --backends gl:egl:llvmpipe,gl:egl:softpipe " +
                           "--no-variants --out " + (dir / "out").string(),
                       std::string("RASTERCHECK_GL_FAULT=crash=") + kVictim);
  EXPECT_EQ(r.code, 3) << r.out;
  const json report = json::parse(std::ifstream(dir / "out" / "report.json"));
  ASSERT_EQ(report["results"].size(), 6u);
  int errors = 0;
  for (const json& row : report["results"]) {
    SCOPED_TRACE(row.dump());
    if (row["fixture"] == kVictim) {
      ++errors;
      EXPECT_EQ(row["status"], "error");
      EXPECT_NE(row["error"].get<std::string>().find("crashed (Segmentation fault)"),
                std::string::npos);
    } else {
      // The fixture after the crash was rendered by a new worker for the same backend.
      EXPECT_NE(row["status"], "error");
    }
  }
  EXPECT_EQ(errors, 2);
  fs::remove_all(dir);
}

// DIR/inputs holding one fixture llvmpipe renders within tolerance, as a.json.
fs::path inputsWithTheFan(const fs::path& dir) {
  fs::path inputs = dir / "inputs";
  fs::create_directories(inputs);
  fs::copy_file(catalog("coverage/triangle_fan.json"), inputs / "a.json");
  return inputs;
}

// `run` starts its GL workers on the variant probes while it checks the fixtures; a bad
// fixture still ends the run with exit 2, one line, no report folder, and no worker left
// behind, even one stuck in a render (hang_once: the first render of each fixture hangs,
// after leaving a marker in TMPDIR). The check cannot end before a worker has begun to draw:
// its mesh importer (RASTERCHECK_MESH_IMPORTER) is a script that waits for that marker,
// then fails, which refuses the fixture naming the mesh.
TEST(GlWorkers, ABadFixtureEndsTheRunWhileTheWorkersDrawTheProbes) {
  const fs::path dir = scratch("bad_beside_probes");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  const fs::path inputs = inputsWithTheFan(dir);
  std::ofstream(inputs / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(inputs / "b.json") << R"({"format": "rastercheck-scene/1",
    "image": {"width": 8, "height": 8}, "camera": {"eye": [0, 0, 5]},
    "objects": [{"mesh": {"file": "tri.obj"}}]})";
  const fs::path tmp = dir / "tmp";
  fs::create_directories(tmp);
  const fs::path importer = dir / "importer.sh";
  std::ofstream(importer) << "#!/bin/sh\n"
                             "for i in $(seq 600); do\n"
                             "  ls \"$TMPDIR\" | grep -q rastercheck-hang-once && exit 1\n"
                             "  sleep 0.1\n"
                             "done\n"
                             "exit 1\n";
  fs::permissions(importer, fs::perms::owner_all);
  const auto start = std::chrono::steady_clock::now();
  const Result r =
      run("run " + inputs.string() + " --backends gl:egl:llvmpipe,gl:egl:softpipe --out " +
              (dir / "out").string(),
          "TMPDIR=" + tmp.string() + " RASTERCHECK_GL_FAULT=hang_once=* " +
              "RASTERCHECK_MESH_IMPORTER=" + importer.string());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("the mesh importer failed"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out"));
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir)) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"importer.sh", "inputs", "probe", "tmp"}));
  bool drew = false;  // a worker began a render before the check ended
  for (const auto& e : fs::directory_iterator(tmp))
    drew = drew || e.path().filename().string().rfind("rastercheck-hang-once-", 0) == 0;
  EXPECT_TRUE(drew);
  EXPECT_LT(seconds, 50.0) << "the run waited for a stuck worker";
  // No process of the run is left: none has this test's TMPDIR in its environment.
  const std::string mine = "TMPDIR=" + tmp.string();
  for (const auto& e : fs::directory_iterator("/proc")) {
    std::ifstream env(e.path() / "environ", std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(env), {}};
    std::size_t at = 0;
    for (std::size_t end; (end = text.find('\0', at)) != std::string::npos; at = end + 1)
      EXPECT_NE(text.substr(at, end - at), mine) << e.path();
  }
  fs::remove_all(dir);
}

// A fixture that has passed the check is rendered while the others are still checked: b's
// mesh import (a script that waits for a's render to begin, then runs the real importer)
// cannot end before a worker draws a (hang_once leaves its marker, then that render hangs
// until --timeout). Rendering only after the check, the script would wait its minute out
// and fail, and the run would exit 2.
TEST(GlWorkers, FixturesThatPassedTheCheckAreRenderedWhileTheRestIsChecked) {
  const fs::path dir = scratch("early_renders");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  const fs::path inputs = inputsWithTheFan(dir);
  std::ofstream(inputs / "tri.obj") << "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(inputs / "b.json") << R"({"format": "rastercheck-scene/1", "name": "early/b",
    "image": {"width": 8, "height": 8}, "camera": {"eye": [0, 0, 5]},
    "objects": [{"mesh": {"file": "tri.obj"}}]})";
  const fs::path tmp = dir / "tmp";
  fs::create_directories(tmp);
  const fs::path importer = dir / "importer.sh";
  const fs::path real = fs::path(RC_EXE).parent_path() / "rastercheck-mesh-import";
  std::ofstream(importer) << "#!/bin/sh\n"
                             "for i in $(seq 600); do\n"
                             "  if ls \"$TMPDIR\" | grep -q rastercheck-hang-once; then\n"
                             "    exec "
                          << real.string()
                          << " \"$@\"\n"
                             "  fi\n"
                             "  sleep 0.1\n"
                             "done\n"
                             "exit 1\n";
  fs::permissions(importer, fs::perms::owner_all);
  const Result r =
      run("run " + inputs.string() + " --backends gl:egl:llvmpipe --timeout 3 --out " +
              (dir / "out").string(),
          "TMPDIR=" + tmp.string() + " RASTERCHECK_GL_FAULT=hang_once=coverage/triangle_fan " +
              "RASTERCHECK_MESH_IMPORTER=" + importer.string());
  ASSERT_TRUE(fs::exists(dir / "out" / "report.json")) << r.out;
  const json report = json::parse(std::ifstream(dir / "out" / "report.json"));
  std::map<std::string, std::string> status;
  for (const json& row : report["results"]) status[row["fixture"]] = row["status"];
  // The render that hung, then its retry (run's --retries) that drew.
  EXPECT_EQ(status["coverage/triangle_fan"], "flake") << r.out;
  EXPECT_EQ(status["early/b"], "pass") << r.out;
  fs::remove_all(dir);
}

// A report folder inside the input folder is output, not input: neither this run's staged
// variant probes (written before the fixtures are found) nor an earlier run's are fixtures.
TEST(GlWorkers, AReportFolderInsideTheInputsHoldsNoFixture) {
  const fs::path dir = scratch("out_inside");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  const fs::path inputs = inputsWithTheFan(dir);
  for (int k = 0; k < 2; ++k) {
    const Result r = run("run " + inputs.string() + " --backends gl:egl:llvmpipe --out " +
                         (inputs / "out").string());
    EXPECT_EQ(r.code, 0) << r.out;
    ASSERT_TRUE(fs::exists(inputs / "out" / "variants" / "probes"));
    const json report = json::parse(std::ifstream(inputs / "out" / "report.json"));
    std::vector<std::string> fixtures;
    for (const json& row : report["results"]) fixtures.push_back(row["fixture"]);
    EXPECT_EQ(fixtures, std::vector<std::string>{"coverage/triangle_fan"}) << "run " << k;
  }
  fs::remove_all(dir);
}

TEST(GlWorkers, TheFaultsHangAndCrashARenderOnTheirOwn) {
  const fs::path dir = scratch("faults");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  const std::string render = "render " + catalog("zbuffer/interpenetrating_ab.json") +
                             " --backend gl:egl:llvmpipe --out " + (dir / "f").string();
  const Result crashed = run(render, std::string("RASTERCHECK_GL_FAULT=crash=") + kVictim);
  EXPECT_EQ(crashed.code, 128 + 11) << crashed.out;  // SIGSEGV
  const Result hung = rc::test::runShell(std::string("RASTERCHECK_GL_FAULT=hang=") + kVictim +
                                         " timeout -s KILL 3 " RC_EXE " " + render);
  EXPECT_EQ(hung.code, 128 + 9) << hung.out;  // killed by timeout(1)
  // Another fixture is not hit.
  const Result other = run("render " + catalog("coverage/triangle_fan.json") +
                               " --backend gl:egl:llvmpipe --out " + (dir / "g").string(),
                           std::string("RASTERCHECK_GL_FAULT=crash=") + kVictim);
  EXPECT_EQ(other.code, 0) << other.out;
  fs::remove_all(dir);
}

// A request's own fault (the mutation study's faulted renders) applies to that render
// alone: one worker renders clean, faulted, clean, and the two clean frames are the same
// to the bit while the faulted one differs and says it was faulted.
TEST(GlWorkers, ARequestsFaultAppliesToThatRenderAlone) {
  const fs::path dir = scratch("request_fault");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  rc::WorkerPool pool(poolOptions(dir));
  const fs::path fixture = catalog("shading/sphere_gouraud_low.json");
  auto render = [&](const std::string& fault) {
    rc::RenderOutcome o = pool.renderAll({{fixture, "gl:egl:llvmpipe", fault}}).front();
    EXPECT_TRUE(o.ok) << o.error;
    return o.frame;
  };
  const rc::Frame before = render("");
  const rc::Frame faulted = render("light_scale=1.5");
  const rc::Frame after = render("");
  EXPECT_EQ(pool.workersStarted(), 1);
  EXPECT_FALSE(before.meta.contains("fault_injected"));
  EXPECT_TRUE(faulted.meta.contains("fault_injected")) << faulted.meta.dump();
  EXPECT_FALSE(after.meta.contains("fault_injected"));
  EXPECT_NE(faulted.color, before.color) << "every light 50 % brighter changed nothing";
  EXPECT_EQ(after.color, before.color);
  EXPECT_EQ(after.depth, before.depth);
  EXPECT_EQ(after.id, before.id);
  // A setting the worker cannot parse is that request's input error, not the worker's end.
  const rc::RenderOutcome bad = pool.renderAll({{fixture, "gl:egl:llvmpipe", "no_such=1"}}).front();
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.error.find("no_such"), std::string::npos) << bad.error;
  EXPECT_EQ(render("").color, before.color);
  EXPECT_EQ(pool.workersStarted(), 1);
  fs::remove_all(dir);
}

// Two random scenes whose failures on llvmpipe and zink were gaps in the reference's
// allowances, not the drivers' (docs/tolerances.md section 11): s20261339 scene 00030 (a
// point a third of a texel outside its shadow map, drawn by llvmpipe as its square's part
// inside: the map's range is open there) and s20261341 scene 00039 (wide polygon-mode lines
// whose colour slack reaches a parameter where another driver's map lights the fragment),
// and one of the comparator's: s20261355 scene 00027 (a polygon-mode line's end only the
// reference draws, under fragments that write no depth: docs/tolerances.md, "Blended
// pixels"). They pass on both drivers now (they failed by 258 units, 47 units and 53086 d16
// steps).
TEST(GlWorkers, CampaignScenesThatShowedReferenceGapsPass) {
  const fs::path dir = scratch("reference_gaps");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  for (const auto& [seed, first] :
       {std::pair{20261339, 30}, std::pair{20261341, 39}, std::pair{20261355, 27}}) {
    const Result g =
        run(fmt::format("generate --seed {} --first {} --count 1 --max-size 200x150 "
                        "--out {}",
                        seed, first, (dir / "scenes" / std::to_string(seed)).string()));
    ASSERT_EQ(g.code, 0) << g.out;
  }
  const Result r =
      run("run " + (dir / "scenes").string() +
          " --backends gl:egl:llvmpipe,gl:egl:zink --no-variants --out " + (dir / "out").string());
  const json report = json::parse(std::ifstream(dir / "out" / "report.json"));
  ASSERT_EQ(report["results"].size(), 6u) << r.out;
  for (const json& row : report["results"])
    EXPECT_NE(row["status"], "fail") << row["fixture"] << " " << row["actual"] << "\n" << r.out;
  fs::remove_all(dir);
}

// A worker sends a multi-pass scene's frame pass alone: its callers compare that one, and the
// pass frames (a 128x128 target here, the reference's with its uncertainty channels) are
// `render --all-passes`'s. In-process, both renderers keep them.
TEST(GlWorkers, AWorkerSendsTheFramePassWithoutThePassFrames) {
  const fs::path dir = scratch("frame_pass_only");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  rc::WorkerPool pool(poolOptions(dir));
  const fs::path fixture = catalog("multipass/mirror_quad.json");
  for (const char* spec : {"ref", "gl:egl:llvmpipe"}) {
    SCOPED_TRACE(spec);
    const rc::RenderOutcome o = pool.renderAll({{fixture, spec, ""}}).front();
    ASSERT_TRUE(o.ok) << o.error;
    EXPECT_EQ(o.frame.width, 200);
    EXPECT_EQ(o.frame.height, 150);
    EXPECT_TRUE(o.frame.passes.empty());
  }
  const Result r = run("render " + fixture.string() + " --backend ref --all-passes --out " +
                       (dir / "all").string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "all" / "passes" / "0-mirror" / "frame.exr")) << r.out;
  fs::remove_all(dir);
}

// Isolation through `run`'s own workers: one worker per driver renders random scenes of
// every profile and the whole catalog in file order, then the same list shuffled, then A, B,
// A for a blended and a textured scene, and every frame must be the bits a worker with a new
// context per render (RASTERCHECK_GL_CONTEXT=new) gives. Where the driver keeps its context
// (llvmpipe, zink, softpipe with the harness's flush and facing reset, docs/gl_backend.md) this
// is what allows it. Tried: with the front face set only for
// clockwise scenes it fails on llvmpipe.
TEST(GlWorkers, FramesDoNotDependOnTheOrderAWorkerDrawsThem) {
  const fs::path dir = scratch("isolation");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  std::vector<fs::path> files =
      rc::test::randomAndCatalog(dir / "random", 20261205, 4, catalog(""));
  ASSERT_GE(files.size(), 60u);
  auto bytes = [](const rc::RenderOutcome& o) {
    return o.ok ? rc::test::framePlanes(o.frame) : "error: " + o.error;
  };
  for (const char* spec :
       {"gl:egl:llvmpipe", "gl:egl:softpipe", "gl:egl:zink", "gl:osmesa:llvmpipe"}) {
    SCOPED_TRACE(spec);
    auto renderList = [&](rc::WorkerPool& pool, const std::vector<std::size_t>& order) {
      std::vector<rc::RenderRequest> requests;
      requests.reserve(order.size());
      for (const std::size_t i : order) requests.push_back({files[i], spec, ""});
      std::vector<std::string> out(files.size());
      const std::vector<rc::RenderOutcome> got = pool.renderAll(requests);
      for (std::size_t k = 0; k < order.size(); ++k) out[order[k]] = bytes(got[k]);
      return out;
    };
    std::vector<std::size_t> order(files.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    const rc::WorkerPool::Options options = poolOptions(dir);
    // What each scene gives in a new context of its own.
    std::vector<std::string> fresh;
    {
      rc::WorkerPool::Options o = options;
      o.environment.emplace_back("RASTERCHECK_GL_CONTEXT=new");
      rc::WorkerPool new_contexts(o);
      fresh = renderList(new_contexts, order);
    }
    rc::WorkerPool pool(options);
    const std::vector<std::string> in_order = renderList(pool, order);
    std::mt19937 rng(11);
    std::shuffle(order.begin(), order.end(), rng);
    const std::vector<std::string> shuffled = renderList(pool, order);
    for (std::size_t i = 0; i < files.size(); ++i) {
      EXPECT_TRUE(in_order[i] == fresh[i]) << files[i].string() << " (file order)";
      EXPECT_TRUE(shuffled[i] == fresh[i]) << files[i].string() << " (shuffled)";
    }
    // A, B, A: a blended rgba8 scene, a textured one, the blended one again.
    const auto index = [&](const std::string& rel) {
      return static_cast<std::size_t>(std::find(files.begin(), files.end(), catalog(rel)) -
                                      files.begin());
    };
    const std::size_t a = index("transparency/rgba8_four_layers.json");
    const std::size_t b = index("texture/checker_grazing_linear_repeat.json");
    ASSERT_LT(a, files.size());
    ASSERT_LT(b, files.size());
    const std::vector<rc::RenderOutcome> aba =
        pool.renderAll({{files[a], spec, ""}, {files[b], spec, ""}, {files[a], spec, ""}});
    EXPECT_TRUE(bytes(aba[0]) == fresh[a] && bytes(aba[1]) == fresh[b] &&
                bytes(aba[2]) == fresh[a]);
    EXPECT_EQ(pool.workersStarted(), 1);
  }
  fs::remove_all(dir);
}

// `run`'s workers choose llvmpipe's rasterizer threads (none where every core already runs a
// render: app/worker_pool.cpp), which is only allowed because the thread count does not
// change a frame: random scenes of every profile and the whole catalog, rendered by workers
// without rasterizer threads and by workers with three, must give the same bits on llvmpipe
// and zink (lavapipe rasterizes like llvmpipe), and frame.json says what the worker had.
TEST(GlWorkers, RasterizerThreadsDoNotChangeTheBits) {
  const fs::path dir = scratch("rasterizer_threads");
  if (!llvmpipeRuns(dir)) GTEST_SKIP() << "llvmpipe does not start here";
  std::vector<fs::path> files =
      rc::test::randomAndCatalog(dir / "random", 20261206, 2, catalog(""));
  ASSERT_GE(files.size(), 50u);
  for (const char* spec : {"gl:egl:llvmpipe", "gl:egl:zink"}) {
    SCOPED_TRACE(spec);
    std::vector<rc::RenderRequest> requests;
    requests.reserve(files.size());
    for (const fs::path& f : files) requests.push_back({f, spec, ""});
    auto renderWith = [&](const std::string& threads) {
      rc::WorkerPool::Options o = poolOptions(dir);
      o.environment.push_back("LP_NUM_THREADS=" + threads);
      rc::WorkerPool pool(o);
      return pool.renderAll(requests);
    };
    const std::vector<rc::RenderOutcome> none = renderWith("0");
    const std::vector<rc::RenderOutcome> three = renderWith("3");
    ASSERT_EQ(none.size(), files.size());
    ASSERT_EQ(three.size(), files.size());
    int rendered = 0;
    for (std::size_t i = 0; i < files.size(); ++i) {
      SCOPED_TRACE(files[i].string());
      ASSERT_EQ(none[i].ok, three[i].ok) << none[i].error << " / " << three[i].error;
      if (!none[i].ok) continue;  // not supported (zink's multisampling on Mesa 22)
      ++rendered;
      EXPECT_EQ(none[i].frame.meta["lp_num_threads"], "0");
      EXPECT_EQ(three[i].frame.meta["lp_num_threads"], "3");
      EXPECT_TRUE(rc::test::framePlanes(none[i].frame) == rc::test::framePlanes(three[i].frame));
    }
    EXPECT_GE(rendered, 40);
  }
  // Without a setting of the user's, a pool that runs a render per core gives its workers none.
  if (std::getenv("LP_NUM_THREADS") == nullptr) {
    rc::WorkerPool::Options o = poolOptions(dir);
    o.max_busy = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    rc::WorkerPool pool(o);
    const rc::RenderOutcome got =
        pool.renderAll({{catalog("coverage/triangle_fan.json"), "gl:egl:llvmpipe", ""}}).front();
    ASSERT_TRUE(got.ok) << got.error;
    EXPECT_EQ(got.frame.meta["lp_num_threads"], "0");
  }
  fs::remove_all(dir);
}

// `run --retries` and deqp-runner's files through the command (docs/ci.md): flaky renders
// told apart from failures (test faults flaky=NAME, a render whose bits change every time,
// and hang_once=NAME, a hang that happens once; drop_primitive, a failure that is the same
// every time), results.csv and failures.csv, a baseline written by hand with every status, a
// round trip of results.csv as the next run's baseline, skips, flakes, caselists and
// --fraction.

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// results.csv as name -> status (and every line checked for deqp-runner's three columns).
std::map<std::string, std::string> resultsOf(const fs::path& out) {
  std::map<std::string, std::string> m;
  std::istringstream in(readText(out / "results.csv"));
  std::string line, previous;
  while (std::getline(in, line)) {
    const std::size_t a = line.find(','), b = line.rfind(',');
    EXPECT_TRUE(a != std::string::npos && b != a) << line;
    const std::string name = line.substr(0, a);
    EXPECT_LT(previous, name) << "sorted by name";
    previous = name;
    EXPECT_NO_THROW((void)std::stod(line.substr(b + 1))) << line;
    m[name] = line.substr(a + 1, b - a - 1);
  }
  return m;
}

std::map<std::string, json> rowsOf(const fs::path& out) {
  const json report = json::parse(std::ifstream(out / "report.json"));
  std::map<std::string, json> m;
  for (const json& row : report["results"]) m[row["fixture"].get<std::string>()] = row;
  return m;
}

const std::vector<std::string> kNames = {"coverage/triangle_fan", "zbuffer/interpenetrating_ab",
                                         "shading/sphere_gouraud_low",
                                         "texture/checker_grazing_nearest_repeat"};
std::string fixtures() {
  std::string s;
  for (const std::string& n : kNames) s += " " + catalog(n + ".json");
  return s;
}
std::string test(const std::string& name) { return name + "@gl:egl:llvmpipe"; }

class RunFlakes : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch(::testing::UnitTest::GetInstance()->current_test_info()->name());
    if (!llvmpipeRuns(dir_)) GTEST_SKIP() << "llvmpipe does not start here";
  }
  fs::path dir_;
};

// Every render of the flaky fixture differs: the pair fails once, its retry gives other bits,
// and it is a flake (its own status, attempts with two digests, the differing pixels), which
// does not fail the run. A dropped triangle fails the same way twice and stays a failure.
TEST_F(RunFlakes, ChangingBitsAreAFlakeTheSameFailureIsNot) {
  const fs::path out = dir_ / "out";
  const Result r =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --out " + out.string(),
          "RASTERCHECK_GL_FAULT=flaky=shading/sphere_gouraud_low");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("1 flake"), std::string::npos) << r.out;
  auto rows = rowsOf(out);
  const json& flake = rows["shading/sphere_gouraud_low"];
  EXPECT_EQ(flake["status"], "flake") << flake.dump(1);
  ASSERT_EQ(flake["attempts"].size(), 2u);
  EXPECT_NE(flake["attempts"][0]["digest"], flake["attempts"][1]["digest"]);
  EXPECT_GE(flake["flake"]["differing_pixels"].get<int>(), 1);
  EXPECT_LE(flake["flake"]["differing_pixels"].get<int>(), 2);
  for (const json& a : flake["attempts"])
    EXPECT_TRUE(fs::exists(out / a["frame"].get<std::string>() / "frame.exr")) << a.dump();
  for (const std::string& n : kNames)
    if (n != "shading/sphere_gouraud_low") {
      EXPECT_EQ(rows[n]["status"], "pass") << n;
    }
  EXPECT_EQ(resultsOf(out)[test("shading/sphere_gouraud_low")], "Flake");
  EXPECT_EQ(readText(out / "failures.csv"), "") << "a flake is a success, as in deqp-runner";
  const std::string junit = readText(out / "junit.xml");
  EXPECT_NE(junit.find("type=\"flake\""), std::string::npos);

  // Deterministic: the same failure on every render (drop_primitive) is retried, agrees,
  // and stays a failure; --retries 0 renders once.
  const fs::path det = dir_ / "det";
  const Result d =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --out " + det.string(),
          "RASTERCHECK_GL_FAULT=drop_primitive=1");
  EXPECT_EQ(d.code, 1) << d.out;
  for (const auto& [name, row] : rowsOf(det)) {
    SCOPED_TRACE(name);
    EXPECT_NE(row["status"], "flake");
    if (row["status"] == "fail") {
      ASSERT_EQ(row["attempts"].size(), 2u);
      EXPECT_EQ(row["attempts"][0]["digest"], row["attempts"][1]["digest"]);
    }
  }
  EXPECT_NE(readText(det / "failures.csv").find(",Fail\n"), std::string::npos);
  const fs::path once = dir_ / "once";
  const Result o = run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants " +
                           "--retries 0 --out " + once.string(),
                       "RASTERCHECK_GL_FAULT=flaky=shading/sphere_gouraud_low");
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_EQ(rowsOf(once)["shading/sphere_gouraud_low"]["status"], "fail");
}

// A hang that happens once: the first render times out, the retry in a fresh worker
// renders and passes: a flake (first attempt an error, second a digest), exit 0.
TEST_F(RunFlakes, AHangThatHappensOnceIsAFlake) {
  const fs::path out = dir_ / "out";
  const fs::path tmp = dir_ / "tmp";
  fs::create_directories(tmp);
  const Result r =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants " +
              "--timeout 10 --out " + out.string(),
          "TMPDIR=" + tmp.string() + " RASTERCHECK_GL_FAULT=hang_once=zbuffer/interpenetrating_ab");
  EXPECT_EQ(r.code, 0) << r.out;
  const json row = rowsOf(out)["zbuffer/interpenetrating_ab"];
  EXPECT_EQ(row["status"], "flake") << row.dump(1);
  ASSERT_EQ(row["attempts"].size(), 2u);
  EXPECT_NE(row["attempts"][0]["error"].get<std::string>().find("timed out"), std::string::npos);
  EXPECT_TRUE(row["attempts"][1].contains("digest"));
  EXPECT_EQ(row["shading"]["status"], "pass") << "compared from the retry that rendered";
}

// A Mesa-style baseline written by hand (fails, flakes, skips), every status: expected
// failures, an unexpected pass, a regression, a known flake, a skip, an expected crash.
TEST_F(RunFlakes, AHandWrittenBaselineGivesEveryStatus) {
  std::ofstream(dir_ / "fails.txt") << "# deqp-runner baseline\n"
                                    << test("coverage/triangle_fan") << ",Fail\n"
                                    << test("zbuffer/interpenetrating_ab") << ",Fail\n"
                                    << test("shading/sphere_gouraud_low") << ",Crash\n"
                                    << "\n";
  std::ofstream(dir_ / "flakes.txt") << "# known flakes\nsphere_flat_low@\n";
  std::ofstream(dir_ / "skips.txt") << "^texture/checker_grazing_linear_clamp@\n";
  const std::string files = " --baseline " + (dir_ / "fails.txt").string() + " --flakes " +
                            (dir_ / "flakes.txt").string() + " --skips " +
                            (dir_ / "skips.txt").string();
  const fs::path out = dir_ / "out";
  // Triangle 5 dropped: triangle_fan (12 triangles) fails, as listed; interpenetrating_ab
  // and the checker (2 each) pass, the first listed (UnexpectedPass); sphere_gouraud_low
  // crashes (listed Crash: ExpectedFail); sphere_flat_low renders wrong (flaky, rendered
  // once), unlisted, but a flakes pattern matches it (KnownFlake); checker_grazing_linear_clamp
  // is skipped.
  const Result r =
      run("run" + fixtures() + " " + catalog("shading/sphere_flat_low.json") + " " +
              catalog("texture/checker_grazing_linear_clamp.json") +
              " --backends gl:egl:llvmpipe --no-variants --retries 0 --out " + out.string() + files,
          "RASTERCHECK_GL_FAULT=drop_primitive=5,crash=shading/sphere_gouraud_low,"
          "flaky=shading/sphere_flat_low");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("does not match baseline: 1 unexpected"), std::string::npos) << r.out;
  std::map<std::string, std::string> got = resultsOf(out);
  EXPECT_EQ(got[test("coverage/triangle_fan")], "ExpectedFail");
  EXPECT_EQ(got[test("zbuffer/interpenetrating_ab")], "UnexpectedPass");
  EXPECT_EQ(got[test("shading/sphere_gouraud_low")], "ExpectedFail");
  EXPECT_EQ(got[test("shading/sphere_flat_low")], "KnownFlake");
  EXPECT_EQ(got[test("texture/checker_grazing_nearest_repeat")], "Pass");
  EXPECT_EQ(got[test("texture/checker_grazing_linear_clamp")], "Skip");
  EXPECT_EQ(readText(out / "failures.csv"),
            test("zbuffer/interpenetrating_ab") + ",UnexpectedPass\n");
  const json report = json::parse(std::ifstream(out / "report.json"));
  EXPECT_EQ(report["runner"]["matches_baseline"], false);
  EXPECT_EQ(report["exit_code"], 1);

  // A new crash nobody expected: exit 3. (Without the baseline's Crash line.)
  std::ofstream(dir_ / "fails2.txt") << test("coverage/triangle_fan") << ",Fail\n";
  const Result crash =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --retries 0 --out " +
              (dir_ / "out2").string() + " --baseline " + (dir_ / "fails2.txt").string(),
          "RASTERCHECK_GL_FAULT=crash=shading/sphere_gouraud_low");
  EXPECT_EQ(crash.code, 3) << crash.out;
  EXPECT_EQ(resultsOf(dir_ / "out2")[test("shading/sphere_gouraud_low")], "Crash");
  EXPECT_EQ(resultsOf(dir_ / "out2")[test("coverage/triangle_fan")], "UnexpectedPass");

  // Bad files are bad input: exit 2, one line naming file and line, nothing written.
  std::ofstream(dir_ / "bad.txt") << "a,Fail\nb Fail\n";
  const Result bad = run("run" + fixtures() + " --backends gl:egl:llvmpipe --out " +
                         (dir_ / "out3").string() + " --baseline " + (dir_ / "bad.txt").string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find((dir_ / "bad.txt").string() + ":2:"), std::string::npos) << bad.out;
  EXPECT_FALSE(fs::exists(dir_ / "out3" / "report.json"));
}

// deqp-runner's round trip: a run's results.csv as the next run's baseline matches (exit 0),
// though the run has failures.
TEST_F(RunFlakes, ResultsCsvRoundTripsAsTheBaseline) {
  const std::string fault = "RASTERCHECK_GL_FAULT=drop_primitive=1";
  const fs::path first = dir_ / "first";
  const Result a =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --out " + first.string(),
          fault);
  EXPECT_EQ(a.code, 1) << a.out;
  ASSERT_FALSE(readText(first / "failures.csv").empty());
  const fs::path second = dir_ / "second";
  const Result b = run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --out " +
                           second.string() + " --baseline " + (first / "results.csv").string(),
                       fault);
  EXPECT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("deqp-runner: matches baseline"), std::string::npos) << b.out;
  EXPECT_EQ(readText(second / "failures.csv"), "");
  for (const auto& [name, status] : resultsOf(second))
    EXPECT_TRUE(status == "Pass" || status == "Warn" || status == "ExpectedFail") << name;
}

// A caselist picks and orders the fixtures; --fraction N --fraction-start M keeps the list's
// entries M, M + N, ... (deqp-runner's meaning); an unknown name is bad input.
TEST_F(RunFlakes, CaselistAndFraction) {
  std::ofstream(dir_ / "cases.txt") << "# three of the four, the last first\n"
                                    << "texture/checker_grazing_nearest_repeat\n\n"
                                    << "coverage/triangle_fan\n"
                                    << "shading/sphere_gouraud_low\n";
  const fs::path out = dir_ / "out";
  const Result r =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --caselist " +
          (dir_ / "cases.txt").string() + " --fraction 2 --fraction-start 1 --out " + out.string());
  EXPECT_EQ(r.code, 0) << r.out;
  const json report = json::parse(std::ifstream(out / "report.json"));
  ASSERT_EQ(report["results"].size(), 2u);
  EXPECT_EQ(report["results"][0]["fixture"], "texture/checker_grazing_nearest_repeat");
  EXPECT_EQ(report["results"][1]["fixture"], "shading/sphere_gouraud_low");
  const Result second =
      run("run" + fixtures() + " --backends gl:egl:llvmpipe --no-variants --caselist " +
          (dir_ / "cases.txt").string() + " --fraction 2 --fraction-start 2 --out " +
          (dir_ / "out2").string());
  const json other = json::parse(std::ifstream(dir_ / "out2" / "report.json"));
  ASSERT_EQ(other["results"].size(), 1u);
  EXPECT_EQ(other["results"][0]["fixture"], "coverage/triangle_fan");

  std::ofstream(dir_ / "bad.txt") << "coverage/triangle_fan\nno/such_fixture\n";
  const Result bad = run("run" + fixtures() + " --backends gl:egl:llvmpipe --caselist " +
                         (dir_ / "bad.txt").string() + " --out " + (dir_ / "out3").string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("bad.txt:2: no fixture named \"no/such_fixture\""), std::string::npos)
      << bad.out;
}

}  // namespace
