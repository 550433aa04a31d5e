// Every input a fuzzer ever found a problem with (tests/fuzz/regressions/<target>/),
// replayed through the same entry point in the ordinary build: each must now be accepted
// or refused with one safe line (fuzz_entries.h aborts otherwise). Also the seeds that
// stand for each target, so that the replay itself is known to reach the code.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/fuzz/fuzz_entries.h"

namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytesOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int replay(const std::string& target, void (*entry)(const std::uint8_t*, std::size_t)) {
  int n = 0;
  const fs::path dir = fs::path(RC_SOURCE_DIR) / "tests/fuzz/regressions" / target;
  if (!fs::is_directory(dir)) return 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename() == "README.md") continue;
    SCOPED_TRACE(e.path().string());
    const std::vector<std::uint8_t> bytes = bytesOf(e.path());
    entry(bytes.data(), bytes.size());
    ++n;
  }
  return n;
}

}  // namespace

TEST(FuzzRegressions, FixtureInputs) {
  const int n = replay("fixture", rc::fuzz::loadFixtureBytes);
  RecordProperty("inputs", n);
}

TEST(FuzzRegressions, MeshInputs) {
  const int n = replay("mesh", rc::fuzz::importMeshBytes);
  RecordProperty("inputs", n);
}

// Inputs on which the in-process fuzzer stopped inside Assimp (a crash, an allocation over
// the importer's limit) and which the importer child turns into a one-line refusal
// (scripts/fuzz.sh keeps them in build/fuzz/findings/mesh/contained/). Replayed through the
// child, never used as fuzzing seeds: they would stop the in-process target at once.
TEST(FuzzRegressions, MeshInputsTheChildContains) {
  const int n = replay("mesh-contained", rc::fuzz::importMeshBytes);
  EXPECT_GE(n, 2);
  RecordProperty("inputs", n);
}

TEST(FuzzRegressions, TextureInputs) {
  const int n = replay("texture", rc::fuzz::decodeTextureBytes);
  RecordProperty("inputs", n);
}
