// The rastercheck command as a user meets it: help and version, exit codes 0/2/3,
// one-line errors that name the file and JSON path, and no output left after a failure.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "fixtures/frame_io.h"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code = -1;
  std::string out;  // stdout and stderr together
};

Result run(const std::string& args, const std::string& env = "") {
  const std::string cmd = env + " " RC_EXE " " + args + " 2>&1";
  Result r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
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
