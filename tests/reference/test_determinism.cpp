// Determinism: bit-identical frames on every run, and across optimisation levels (the
// reference compiled again at -O0 and at -O2 into two dump tools, the -O0 one with its own
// -O0 copy of the fixtures sources, so that the camera, model and normal matrices, TRS
// transforms, generators, computed normals and the painter's sort are covered along with
// the renderer).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "reference/reference_renderer.h"
#include "tests/reference/corpus.h"
#include "tests/reference/test_scenes.h"
#include "tests/support/random_fixtures.h"

namespace rc {
namespace {

// The fixture files of the corpus: the whole catalog (perspective cameras, TRS and matrix
// transforms, every generator, OFF/PLY/STL/OBJ imports, meshes without normals).
std::vector<std::filesystem::path> corpusFixtures() {
  return test::fixtureFiles(std::filesystem::path(RC_SOURCE_DIR) / "fixtures" / "scenes");
}

std::string runDump(const char* tool, const std::string& name) {
  const std::filesystem::path out =
      std::filesystem::path(RC_BINARY_DIR) / "tests" / "reference" / name;
  std::string cmd = std::string("\"") + tool + "\" --out \"" + out.string() + "\"";
  for (const auto& f : corpusFixtures()) cmd += " \"" + f.string() + "\"";
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

// The first line where two listings differ, for the failure message.
std::string firstDifference(const std::string& a, const std::string& b) {
  std::istringstream sa(a);
  std::istringstream sb(b);
  std::string la;
  std::string lb;
  while (true) {
    const bool ga = static_cast<bool>(std::getline(sa, la));
    const bool gb = static_cast<bool>(std::getline(sb, lb));
    if (!ga && !gb) return "(none)";
    if (la != lb || ga != gb) return (ga ? la : "(end)") + "  vs  " + (gb ? lb : "(end)");
  }
}

TEST(Determinism, IdenticalAcrossOptimisationLevels) {
  const std::string o0 = runDump(RC_REFERENCE_DUMP_O0, "corpus_O0.txt");
  const std::string o2 = runDump(RC_REFERENCE_DUMP_O2, "corpus_O2.txt");
  const std::vector<std::filesystem::path> fixtures = corpusFixtures();
  ASSERT_GE(fixtures.size(), 20u);
  const std::string here = test::corpusHashes(fixtures, false);
  // 4 option sets x (6 feature scenes + the catalog), one line each.
  EXPECT_EQ(std::count(here.begin(), here.end(), '\n'),
            static_cast<std::ptrdiff_t>(4 * (test::featureScenes().size() + fixtures.size())));
  EXPECT_EQ(o0, o2) << "-O0 and -O2 builds differ first at: " << firstDifference(o0, o2);
  EXPECT_EQ(o0, here) << "the test's build differs from -O0 first at: "
                      << firstDifference(o0, here);
}

// The golden listing (tests/reference/data/golden_frames.txt): one hash over every buffer
// of the frame (colour, depth, id and every uncertainty channel, frameBytes()) per
// catalog fixture, random scene (`generate --seed 1 --count 10` under four profiles; their
// files are pinned by RandomScenes.GoldenHash) and benchmark scene, each under the four
// option sets of renderCorpus(). It was recorded before any of the reference's speed work
// (docs/performance.md) so that this test proves that work changed no bit.
// An intended change of the reference's output re-records it:
//   RC_UPDATE_GOLDEN=1 build/release/tests/reference/test_reference (with
//   --gtest_filter=Determinism.GoldenFrames)
// Fixtures added after the recording are listed (not failed) until it is re-recorded.
std::string goldenListing() {
  namespace fs = std::filesystem;
  const fs::path source(RC_SOURCE_DIR);
  const fs::path random = fs::path(RC_BINARY_DIR) / "tests" / "reference" / "golden_random";
  std::vector<fs::path> files = corpusFixtures();
  const std::size_t catalog = files.size();
  for (const fs::path& f : test::writeRandomProfiles(random, 1, 10)) files.push_back(f);
  EXPECT_GE(files.size(), catalog + 40);
  std::string out;
  test::renderCorpus(files, true, [&](const std::string& name, const Frame& frame) {
    std::string label = name;
    for (const fs::path& base : {random.parent_path(), source}) {
      const std::string prefix = base.string() + "/";
      if (label.starts_with(prefix)) label = label.substr(prefix.size());
    }
    out += fmt::format("{:016x} {}\n", test::frameHash(frame), label);
  });
  fs::remove_all(random);
  return out;
}

std::map<std::string, std::string> parseListing(const std::string& text) {
  std::map<std::string, std::string> hashes;  // name -> hash
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.size() > 17) hashes[line.substr(17)] = line.substr(0, 16);
  return hashes;
}

TEST(Determinism, GoldenFrames) {
  const std::filesystem::path golden =
      std::filesystem::path(RC_SOURCE_DIR) / "tests" / "reference" / "data" / "golden_frames.txt";
  const std::string now = goldenListing();
  if (std::getenv("RC_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(golden, std::ios::binary) << now;
    GTEST_SKIP() << "recorded " << golden;
  }
  std::ifstream in(golden, std::ios::binary);
  ASSERT_TRUE(in) << golden;
  const auto expected = parseListing(std::string(std::istreambuf_iterator<char>(in), {}));
  const auto actual = parseListing(now);
  ASSERT_GE(expected.size(), 4u * 90u);
  std::size_t compared = 0;
  for (const auto& [name, hash] : actual) {
    const auto it = expected.find(name);
    if (it == expected.end()) {
      std::printf("not in the golden listing yet: %s\n", name.c_str());
      continue;
    }
    ++compared;
    EXPECT_EQ(hash, it->second) << name << ": the reference's frame changed";
  }
  for (const auto& [name, hash] : expected)
    EXPECT_TRUE(actual.contains(name)) << name << " is in the golden listing but was not rendered";
  EXPECT_GE(compared, expected.size());
}

TEST(Determinism, TheCorpusIsSensitiveToOneUlp) {
  // The comparison above must be able to fail: nudging one vertex by one float ulp
  // changes the bytes.
  auto scenes = test::featureScenes();
  Scene& s = scenes.back().scene;  // window_random: the first triangle is visible
  const std::string a = test::frameBytes(renderReference(s));
  const std::uint64_t ha = test::frameHash(renderReference(s));
  glm::vec3& p = s.objects[0].mesh.positions[0];
  p.x = std::nextafter(p.x, 100.0f);
  const Frame nudged = renderReference(s);
  EXPECT_FALSE(a == test::frameBytes(nudged));
  EXPECT_NE(ha, test::frameHash(nudged));
}

}  // namespace
}  // namespace rc
