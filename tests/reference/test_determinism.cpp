// Determinism: bit-identical frames on every run, and across optimisation levels (the
// reference sources compiled again at -O0 and at -O2 into two dump tools).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

std::string runDump(const char* tool, const std::string& name) {
  const std::filesystem::path out =
      std::filesystem::path(RC_BINARY_DIR) / "tests" / "reference" / name;
  const std::string cmd = std::string("\"") + tool + "\" \"" + out.string() + "\"";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Determinism, SameScenesTwiceGiveIdenticalBytes) {
  for (const auto& [name, scene] : test::featureScenes()) {
    const std::string a = test::frameBytes(renderReference(scene));
    const std::string b = test::frameBytes(renderReference(scene));
    EXPECT_EQ(a.size(), b.size()) << name;
    EXPECT_TRUE(a == b) << name;
  }
}

TEST(Determinism, IdenticalAcrossOptimisationLevels) {
  const std::string o0 = runDump(RC_REFERENCE_DUMP_O0, "corpus_O0.bin");
  const std::string o2 = runDump(RC_REFERENCE_DUMP_O2, "corpus_O2.bin");
  const std::string here = test::featureCorpusBytes();
  ASSERT_GT(here.size(), 100000u);
  EXPECT_EQ(o0.size(), here.size());
  EXPECT_TRUE(o0 == o2) << "-O0 and -O2 builds differ";
  EXPECT_TRUE(o0 == here) << "the test's build differs from -O0";
}

TEST(Determinism, TheCorpusIsSensitiveToOneUlp) {
  // The comparison above must be able to fail: nudging one vertex by one float ulp
  // changes the bytes.
  auto scenes = test::featureScenes();
  Scene& s = scenes.back().scene;  // window_random: the first triangle is visible
  const std::string a = test::frameBytes(renderReference(s));
  glm::vec3& p = s.objects[0].mesh.positions[0];
  p.x = std::nextafter(p.x, 100.0f);
  EXPECT_FALSE(a == test::frameBytes(renderReference(s)));
}

}  // namespace
}  // namespace rc
