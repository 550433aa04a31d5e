// The GL backend through the `rastercheck render` command, in a child process as a user
// (or `rastercheck run`) meets it: a shader that does not compile and a platform that
// is not there exit 3 with one line naming the fixture; RASTERCHECK_GL_FAULT reaches the
// child, is recorded in frame.json and warned about once; a bad fault list exits 2.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

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
  std::vector<std::string> s = {"gl:egl:llvmpipe", "gl:egl:softpipe"};
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

}  // namespace
