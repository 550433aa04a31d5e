// Checks of the catalog itself, without GL: the expectations file is valid (and its
// validator catches each kind of mistake), the catalog covers every required tag with at
// least 40 described fixtures, and fixtures/README.md is what
// scripts/gen-fixture-readme.sh makes of the catalog today.
#include <sys/wait.h>

#include <cstdio>
#include <map>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "fixtures/catalog.h"
#include "fixtures/loader.h"
#include "tests/conformance/conformance_support.h"

namespace fs = std::filesystem;
using namespace rc;
using namespace rc::conformance;

namespace {

// The topics of the lecture notes that the issue asks the catalog to cover.
const std::vector<std::string> kRequiredTags = {
    "coverage",     "fill-rule",     "subpixel",       "clipping",        "near-plane",
    "culling",      "zbuffer",       "painter",        "depth-precision", "perspective",
    "orthographic", "flat",          "gouraud",        "phong",           "blinn-phong",
    "ambient",      "diffuse",       "specular",       "point-light",     "directional-light",
    "attenuation",  "normal-matrix", "vertex-normals", "texture",         "transparency",
    "real-mesh"};

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += "\n  " + l;
  return out;
}

std::vector<std::string> errorsOf(const char* json) {
  const std::set<std::string> fixtures = {"depth/zfight_d16", "texture/checker"};
  return parseExpectations(nlohmann::json::parse(json), fixtures, knownBackends()).errors;
}

// Runs a shell command; returns its exit code and puts stdout+stderr in `output`.
int run(const std::string& cmd, std::string& output) {
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return -1;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  const int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST(Expectations, FileIsValid) {
  const Expectations& e = expectations();
  EXPECT_TRUE(e.errors.empty()) << expectationsFile().string() << ":" << joinLines(e.errors);
}

TEST(Expectations, ValidEntriesAreAccepted) {
  const auto doc = nlohmann::json::parse(R"({"about": "x", "expectations": [
      {"fixture": "depth/zfight_d16", "backend": "gl:egl:softpipe", "class": "depth",
       "reason": "softpipe's depth slope"},
      {"fixture": "depth/zfight_d16", "backend": "gl:*:llvmpipe", "class": "visibility",
       "reason": "both llvmpipe paths"}]})");
  const Expectations e = parseExpectations(doc, {"depth/zfight_d16"}, knownBackends());
  EXPECT_TRUE(e.errors.empty()) << joinLines(e.errors);
  EXPECT_EQ(e.entries.size(), 2u);
}

TEST(Expectations, EachMistakeIsReported) {
  // One mistake per document; each must produce exactly one error naming its path.
  const std::vector<std::pair<const char*, const char*>> cases = {
      {R"({"expectations": [{"fixture": "depth/nope", "backend": "gl:egl:llvmpipe",
          "class": "depth", "reason": "r"}]})",
       "expectations[0].fixture: no fixture named \"depth/nope\""},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": "gl:egl:llvmpipes",
          "class": "depth", "reason": "r"}]})",
       "expectations[0].backend: \"gl:egl:llvmpipes\" matches none"},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": "gl:*",
          "class": "depth", "reason": "r"}]})",
       "expectations[0].backend: \"gl:*\" matches none"},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": "gl:egl:softpipe",
          "class": "colour", "reason": "r"}]})",
       "expectations[0].class: \"colour\" is not one of"},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": "gl:egl:softpipe",
          "class": "depth", "reason": " "}]})",
       "expectations[0].reason: must say why"},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": "gl:egl:softpipe",
          "class": "depth"}]})",
       "expectations[0].reason: missing"},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": "gl:egl:softpipe",
          "class": "depth", "reason": "r", "why": "x"}]})",
       "expectations[0].why: unknown key"},
      {R"({"expectations": [{"fixture": "depth/zfight_d16", "backend": 3,
          "class": "depth", "reason": "r"}]})",
       "expectations[0].backend: must be a string"},
      {R"({"expectations": [{"fixture": "texture/checker", "backend": "gl:egl:softpipe",
          "class": "depth", "reason": "r"}, {"fixture": "texture/checker",
          "backend": "gl:egl:softpipe", "class": "depth", "reason": "again"}]})",
       "expectations[1]: repeats an earlier entry"},
      {R"({"expectations": [7]})", "expectations[0]: must be an object"},
      {R"({"expectation": []})", "expectations: must be an array"},
      {R"({"expectations": [], "note": 1})", "note: unknown key"},
  };
  for (const auto& [json, want] : cases) {
    const auto errors = errorsOf(json);
    ASSERT_EQ(errors.size(), 1u) << json << joinLines(errors);
    EXPECT_NE(errors[0].find(want), std::string::npos) << errors[0] << "\nwanted: " << want;
  }
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
  std::string output;
  const std::string cmd = fmt::format("RASTERCHECK='{}' '{}/scripts/gen-fixture-readme.sh' --check",
                                      RC_EXE, RC_SOURCE_DIR);
  EXPECT_EQ(run(cmd, output), 0) << output;
}
