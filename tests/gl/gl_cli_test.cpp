// The GL backend through the `rastercheck render` command, in a child process as a user
// (or `rastercheck run`) meets it: a shader that does not compile and a platform that
// is not there exit 3 with one line naming the fixture; RASTERCHECK_GL_FAULT reaches the
// child, is recorded in frame.json and warned about once; a bad fault list exits 2; zink
// starts without a word from the Vulkan loader; a copy of the system's Mesa named with
// "@DIR" is what really loads, and a folder that cannot be used says so in one line.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "fixtures/frame_io.h"
#include "tests/support/command.h"

namespace fs = std::filesystem;

namespace {

using Result = rc::test::CommandResult;  // stdout and stderr together in `out`

Result run(const std::string& args, const std::string& env = "") {
  return rc::test::runShell(env + " " RC_EXE " " + args);
}

const std::string kFixture =
    std::string(RC_SOURCE_DIR) + "/fixtures/scenes/coverage/triangle_fan.json";
const std::string kFixtureName = "coverage/triangle_fan";

// "render FIXTURE --backend SPEC --out OUT"
std::string renderArgs(const std::string& spec, const fs::path& out) {
  std::string args = "render ";
  args += kFixture;
  args += " --backend ";
  args += spec;
  args += " --out ";
  args += out.string();
  return args;
}

// "FIXTURE_NAME: SPEC: what", the start of every backend error of this fixture.
std::string errorPrefix(const std::string& spec, const std::string& what) {
  std::string prefix = kFixtureName;
  prefix += ": ";
  prefix += spec;
  prefix += ": ";
  prefix += what;
  return prefix;
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_gl_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::vector<std::string> specs() {
  std::vector<std::string> s = {"gl:egl:llvmpipe", "gl:egl:softpipe", "gl:egl:zink"};
#ifdef RC_HAVE_OSMESA
  s.insert(s.end(), {"gl:osmesa:llvmpipe", "gl:osmesa:softpipe"});
#endif
  return s;
}

bool requireGl() {
  const char* env = std::getenv("RASTERCHECK_REQUIRE_GL");
  return env != nullptr && std::string(env) == "1";
}

TEST(GlCli, ShaderCompileErrorExitsThreeNamingTheFixture) {
  int ran = 0;  // specs whose driver started: with none, nothing was checked
  for (const std::string& spec : specs()) {
    const fs::path out = scratch("shader") / "frame";
    const Result r = run(renderArgs(spec, out), "RASTERCHECK_GL_FAULT=shader_compile_error");
    EXPECT_EQ(r.code, 3) << spec << ": " << r.out;
    if (r.out.find("does not compile") == std::string::npos) {  // the driver did not start
      if (requireGl()) ADD_FAILURE() << "RASTERCHECK_REQUIRE_GL=1 but " << spec << ": " << r.out;
      continue;
    }
    ++ran;
    // One warning line (a fault is injected), then the one error line.
    const std::vector<std::string> all = lines(r.out);
    const auto error = std::find_if(all.begin(), all.end(), [](const std::string& l) {
      return l.find("does not compile") != std::string::npos;
    });
    ASSERT_NE(error, all.end()) << spec << ": " << r.out;
    EXPECT_NE(error->find(errorPrefix(spec, "fragment shader does not compile")), std::string::npos)
        << *error;
    EXPECT_NE(error->find("rc_injected_compile_error"), std::string::npos)
        << "the compiler's own log: " << *error;
    EXPECT_EQ(all.size(), 2u) << r.out;
    EXPECT_FALSE(fs::exists(out)) << "no half-written output";
    fs::remove_all(out.parent_path());
  }
  if (ran == 0) GTEST_SKIP() << "no GL driver starts here";
}

TEST(GlCli, UnavailablePlatformExitsThreeNamingTheFixture) {
  std::vector<std::string> unavailable = {"gl:egl-device"};
#ifndef RC_HAVE_OSMESA
  unavailable.push_back("gl:osmesa");
#endif
  for (const std::string& spec : unavailable) {
    const fs::path out = scratch("platform") / "frame";
    const Result r = run(renderArgs(spec, out));
    fs::remove_all(out.parent_path());
    // No GPU is attached to the machines this suite runs on; where one is, it renders.
    if (spec == "gl:egl-device" && r.code == 0) continue;
    EXPECT_EQ(r.code, 3) << spec << ": " << r.out;
    EXPECT_EQ(lines(r.out).size(), 1u) << r.out;
    EXPECT_NE(r.out.find(errorPrefix(spec, "")), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out));
  }
}

// softpipe has one sample: `render` of a 4-sample fixture exits 3 with one "not supported"
// line and writes nothing; `run` records a not_supported row (neither pass nor failure:
// exit 0, junit skipped) next to llvmpipe's pass.
TEST(GlCli, TooFewSamplesIsNotSupported) {
  const std::string fixture = std::string(RC_SOURCE_DIR) + "/fixtures/scenes/msaa/edge_slopes.json";
  const fs::path dir = scratch("msaa");
  const Result r =
      run("render " + fixture + " --backend gl:egl:softpipe --out " + (dir / "frame").string());
  if (r.code == 3 && r.out.find("not supported") == std::string::npos) {
    if (requireGl()) FAIL() << "RASTERCHECK_REQUIRE_GL=1 but softpipe: " << r.out;
    GTEST_SKIP() << "softpipe does not start here: " << r.out;
  }
  EXPECT_EQ(r.code, 3) << r.out;
  ASSERT_EQ(lines(r.out).size(), 1u) << r.out;
  EXPECT_EQ(
      r.out.rfind("rastercheck: not supported: msaa/edge_slopes: gl:egl:softpipe: 4 samples", 0),
      0u)
      << r.out;
  EXPECT_FALSE(fs::exists(dir / "frame"));

  const Result ran =
      run("run " + fixture + " --backends gl:egl:llvmpipe,gl:egl:softpipe --no-variants --out " +
          (dir / "report").string());
  EXPECT_EQ(ran.code, 0) << ran.out;
  EXPECT_NE(ran.out.find("1 not supported"), std::string::npos) << ran.out;
  std::ifstream in(dir / "report" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  std::map<std::string, std::string> status;
  for (const nlohmann::json& row : report["results"]) status[row["actual"]] = row["status"];
  EXPECT_EQ(status["gl:egl:llvmpipe"], "pass");
  EXPECT_EQ(status["gl:egl:softpipe"], "not_supported");
  EXPECT_EQ(report["summary"]["not_supported"], 1);
  std::ifstream junit(dir / "report" / "junit.xml");
  const std::string xml((std::istreambuf_iterator<char>(junit)), std::istreambuf_iterator<char>());
  EXPECT_NE(xml.find("<skipped type=\"not supported\""), std::string::npos);
  fs::remove_all(dir);
}

TEST(GlCli, UnknownFaultExitsTwoBeforeWriting) {
  const fs::path out = scratch("badfault") / "frame";
  const Result r =
      run(renderArgs("gl:egl:llvmpipe", out), "RASTERCHECK_GL_FAULT=light_scale=2,frobnicate");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(lines(r.out).size(), 1u) << r.out;
  EXPECT_NE(r.out.find("RASTERCHECK_GL_FAULT: 'frobnicate': unknown fault"), std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(out.parent_path());
}

TEST(GlCli, InjectedFaultIsRecordedAndWarnedOnce) {
  int ran = 0;  // specs whose driver started: with none, nothing was checked
  for (const std::string& spec : specs()) {
    const fs::path dir = scratch("fault");
    const Result clean = run(renderArgs(spec, dir / "clean"));
    if (clean.code != 0) {  // the driver did not start
      if (requireGl())
        ADD_FAILURE() << "RASTERCHECK_REQUIRE_GL=1 but " << spec << ": " << clean.out;
      fs::remove_all(dir);
      continue;
    }
    ++ran;
    const Result r =
        run(renderArgs(spec, dir / "faulted"), "RASTERCHECK_GL_FAULT=drop_primitive=1");
    ASSERT_EQ(r.code, 0) << spec << ": " << r.out;
    const std::vector<std::string> all = lines(r.out);
    EXPECT_EQ(std::count_if(all.begin(), all.end(),
                            [](const std::string& l) {
                              return l.find("warning: GL fault injected (drop_primitive=1)") !=
                                     std::string::npos;
                            }),
              1)
        << r.out;
    const rc::Frame a = rc::readFrameDir(dir / "clean");
    const rc::Frame b = rc::readFrameDir(dir / "faulted");
    EXPECT_FALSE(a.meta.contains("fault_injected"));
    EXPECT_EQ(b.meta.at("fault_injected"), "drop_primitive=1");
    EXPECT_EQ(b.meta.at("driver"), a.meta.at("driver"));
    std::size_t had = 0, has = 0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i) {
      had += a.id[i] == 1 ? 1 : 0;
      has += b.id[i] == 1 ? 1 : 0;
    }
    EXPECT_GT(had, 0u) << spec;
    EXPECT_EQ(has, 0u) << spec;
    fs::remove_all(dir);
  }
  if (ran == 0) GTEST_SKIP() << "no GL driver starts here";
}

TEST(GlCli, ZinkStartsQuietlyWithoutXdgRuntimeDir) {
  // Without XDG_RUNTIME_DIR the Vulkan loader's window-system code prints "error:
  // XDG_RUNTIME_DIR is invalid or not set in the environment." twice on every start; the
  // backend gives zink a private one, so a normal render says exactly its one line.
  const fs::path out = scratch("zink_quiet") / "frame";
  const Result r = run(renderArgs("gl:egl:zink", out), "env -u XDG_RUNTIME_DIR");
  if (r.code != 0 && !requireGl()) GTEST_SKIP() << "zink does not start here: " << r.out;
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(lines(r.out),
            std::vector<std::string>{kFixtureName + ": gl:egl:zink -> " + out.string()})
      << r.out;
  const rc::Frame f = rc::readFrameDir(out);
  EXPECT_EQ(f.meta.at("driver"), "zink");
  const std::string stack = f.meta.at("stack");
  EXPECT_NE(stack.find("zink ("), std::string::npos) << stack;
  EXPECT_NE(stack.find("| Vulkan 1."), std::string::npos) << stack;
  EXPECT_EQ(f.meta.at("vulkan").at("subpixel_precision_bits"), 8);
  fs::remove_all(out.parent_path());
}

// "libEGL_mesa.so.0.0.0" -> "libEGL_mesa.so.0": the name the dynamic loader asks for.
std::string sonameOf(const std::string& file) {
  std::smatch m;
  return std::regex_search(file, m, std::regex(R"(^.*?\.so(\.[0-9]+)?)")) ? m.str(0) : file;
}

// Copies the Mesa libraries a system render of `spec` loaded (frame.json mesa.libraries)
// into dir (the DRI driver into dir/dri), under the names the loader looks for. Only
// `keep` (name prefixes) are copied: the Vulkan loader maps every installed ICD.
void copyMesaOf(const nlohmann::json& mesa, const fs::path& dir,
                const std::vector<std::string>& keep) {
  fs::create_directories(dir / "dri");
  for (const std::string lib : mesa.at("libraries")) {
    const std::string name = fs::path(lib).filename().string();
    if (std::none_of(keep.begin(), keep.end(),
                     [&](const std::string& k) { return name.rfind(k, 0) == 0; }))
      continue;
    const bool dri = fs::path(lib).parent_path().filename() == "dri";
    fs::copy_file(lib, (dri ? dir / "dri" : dir) / sonameOf(name), fs::copy_options::skip_existing);
  }
}

TEST(GlCli, MesaFolderCopyIsWhatLoads) {
  // The system's own Mesa, copied into a temporary folder, stands in for a Mesa build.
  const fs::path dir = scratch("mesa_copy");
  std::vector<std::string> mesa_specs = {"gl:egl:llvmpipe", "gl:egl:zink"};
#ifdef RC_HAVE_OSMESA
  mesa_specs.emplace_back("gl:osmesa:llvmpipe");
#endif
  const fs::path copy = dir / "mesa";
  for (const std::string& spec : mesa_specs) {
    const Result sys = run(renderArgs(spec, dir / ("system_" + spec)));
    if (sys.code != 0 && !requireGl()) GTEST_SKIP() << spec << " does not start: " << sys.out;
    ASSERT_EQ(sys.code, 0) << sys.out;
    const rc::Frame f = rc::readFrameDir(dir / ("system_" + spec));
    copyMesaOf(f.meta.at("mesa"), copy,
               {"libEGL_mesa", "libgbm", "libglapi", "libOSMesa", "libvulkan_lvp", "swrast_dri"});
  }
  const std::string real = fs::canonical(copy).string();
  for (const std::string& spec : mesa_specs) {
    const std::string asked = spec + "@" + copy.string();
    const fs::path out = dir / ("copy_" + spec);
    const Result r = run(renderArgs(asked, out));
    ASSERT_EQ(r.code, 0) << asked << ": " << r.out;
    EXPECT_EQ(lines(r.out).size(), 1u) << r.out;
    const rc::Frame f = rc::readFrameDir(out);
    const nlohmann::json& mesa = f.meta.at("mesa");
    EXPECT_EQ(mesa.at("asked"), copy.string());
    EXPECT_EQ(mesa.at("dir"), real);
    EXPECT_EQ(mesa.at("driver_library").get<std::string>().rfind(real + "/", 0), 0u) << mesa.dump();
    for (const std::string lib : mesa.at("libraries"))
      EXPECT_EQ(lib.rfind(real + "/", 0), 0u) << asked << " loaded " << lib;
    EXPECT_NE(std::string(f.meta.at("stack")).find("(Mesa folder " + real + ")"),
              std::string::npos);
    // The same driver as the system's: the same frame.
    const rc::Frame sys = rc::readFrameDir(dir / ("system_" + spec));
    EXPECT_EQ(f.id, sys.id) << asked;
    EXPECT_EQ(f.color, sys.color) << asked;
  }

  // One run compares the system's llvmpipe with the copy's; report.json says which Mesa
  // each side used.
  const std::string copied = "gl:egl:llvmpipe@" + copy.string();
  const Result r = run("run " + kFixture + " --backends gl:egl:llvmpipe," + copied +
                       " --against gl:egl:llvmpipe --no-variants --out " + (dir / "run").string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(dir / "run" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  ASSERT_EQ(report.at("results").size(), 1u);
  const nlohmann::json& row = report.at("results")[0];
  EXPECT_EQ(row.at("expected"), "gl:egl:llvmpipe");
  EXPECT_EQ(row.at("actual"), copied);
  EXPECT_TRUE(row.at("stacks").at("expected").at("mesa").at("dir").is_null());
  EXPECT_EQ(row.at("stacks").at("actual").at("mesa").at("dir"), real);
  EXPECT_EQ(row.at("stacks")
                .at("actual")
                .at("mesa")
                .at("driver_library")
                .get<std::string>()
                .rfind(real + "/", 0),
            0u);
  if (std::system("/usr/bin/python3 -c 'import jsonschema' 2>/dev/null") == 0) {
    const Result valid = rc::test::runShell(
        "/usr/bin/python3 -c \"import json,sys,jsonschema; jsonschema.validate(json.load(open("
        "sys.argv[1])), json.load(open(sys.argv[2])))\" '" +
        (dir / "run" / "report.json").string() + "' '" RC_SOURCE_DIR "/docs/report-schema.json'");
    EXPECT_EQ(valid.code, 0) << "report.json with stacks against docs/report-schema.json: "
                             << valid.out;
  }

  // What was asked is not what loaded: without dri/ the copy's libEGL_mesa finds the
  // system's driver. Exit 3, one line naming the stray library, nothing written.
  fs::remove_all(copy / "dri");
  const fs::path out = dir / "stray";
  const Result stray = run(renderArgs("gl:egl:llvmpipe@" + copy.string(), out));
  EXPECT_EQ(stray.code, 3) << stray.out;
  EXPECT_EQ(lines(stray.out).size(), 1u) << stray.out;
  EXPECT_NE(stray.out.find("asked for the Mesa in " + real + ", but this process loaded "),
            std::string::npos)
      << stray.out;
  EXPECT_NE(stray.out.find("_dri.so from outside it"), std::string::npos) << stray.out;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(GlCli, UnusableMesaFolderExitsTwoInOneLine) {
  const fs::path dir = scratch("mesa_bad");
  fs::create_directories(dir / "empty");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"gl:egl:llvmpipe@" + (dir / "missing").string(), "does not exist"},
      {"gl:egl:softpipe@" + (dir / "empty").string(), "holds neither libEGL_mesa.so.0"},
      {"gl:egl:bogus", "unknown GL backend 'gl:egl:bogus'"},
  };
  for (const auto& [spec, what] : cases) {
    const Result r = run(renderArgs(spec, dir / "frame"));
    EXPECT_EQ(r.code, 2) << spec << ": " << r.out;
    EXPECT_EQ(lines(r.out).size(), 1u) << r.out;
    EXPECT_NE(r.out.find(what), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "frame"));
    // `run` checks every SPEC before rendering anything.
    std::string args = "run " + kFixture;
    args += " --backends gl:egl:llvmpipe," + spec;
    args += " --out " + (dir / "run").string();
    const Result rr = run(args);
    EXPECT_EQ(rr.code, 2) << rr.out;
    EXPECT_EQ(lines(rr.out).size(), 1u) << rr.out;
    EXPECT_FALSE(fs::exists(dir / "run"));
  }
  fs::remove_all(dir);
}

}  // namespace
