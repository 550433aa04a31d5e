// `rastercheck generate` as a user meets it: the output folder's layout, the same bytes
// for the same seed, a generated folder replaced whole, bad arguments refused in one line
// with exit code 2 and nothing written.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/command.h"

namespace fs = std::filesystem;

namespace {

rc::test::CommandResult run(const std::string& args) {
  return rc::test::runShell(RC_EXE " " + args);
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_gen_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    names.insert(fs::relative(e.path(), dir).generic_string());
  return {names.begin(), names.end()};
}

int lineCount(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

bool hasLeftovers(const fs::path& parent) {
  for (const auto& e : fs::directory_iterator(parent))
    if (e.path().filename().string().find(".staging-") != std::string::npos ||
        e.path().filename().string().find(".old-") != std::string::npos ||
        e.path().filename().string().rfind(".rastercheck-", 0) == 0)
      return true;
  return false;
}

}  // namespace

TEST(CliGenerate, WritesTheLayoutAndTheSameBytesForTheSameSeed) {
  const fs::path dir = scratch("layout");
  const auto r =
      run("generate --seed 5 --count 12 --out " + (dir / "a").string() + " --profile generators");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("wrote 12 fixtures"), std::string::npos) << r.out;
  const std::vector<std::string> files = listing(dir / "a");
  std::vector<std::string> scenes;
  std::size_t textures = 0;
  for (const std::string& f : files) {
    if (f.rfind("generators-s5-", 0) == 0) scenes.push_back(f);
    if (f.rfind("textures/", 0) == 0 && f.size() > 4 && f.substr(f.size() - 4) == ".png")
      ++textures;
  }
  ASSERT_EQ(scenes.size(), 12u);
  EXPECT_EQ(scenes.front(), "generators-s5-00000.json");
  EXPECT_EQ(scenes.back(), "generators-s5-00011.json");
  EXPECT_GE(textures, 10u);
  ASSERT_TRUE(fs::exists(dir / "a" / "generate.json"));
  const auto manifest = nlohmann::json::parse(readFile(dir / "a" / "generate.json"));
  EXPECT_EQ(manifest["seed"], 5);
  EXPECT_EQ(manifest["count"], 12);
  EXPECT_EQ(manifest["profile"], "generators");
  EXPECT_EQ(manifest["tags"]["random"], 12);

  // The listed names come in index order, and every scene loads (list uses the strict loader).
  const auto list = run("list " + (dir / "a").string() + " --json");
  ASSERT_EQ(list.code, 0) << list.out;
  const auto rows = nlohmann::json::parse(list.out);
  ASSERT_EQ(rows.size(), 12u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string index = std::to_string(i);
    EXPECT_EQ(rows[i]["name"],
              "random-generators/s5/" + std::string(5 - index.size(), '0') + index);
  }

  // Another generation with the same arguments: the same files, byte for byte.
  ASSERT_EQ(
      run("generate --seed 5 --count 12 --out " + (dir / "b").string() + " --profile generators")
          .code,
      0);
  ASSERT_EQ(listing(dir / "b"), files);
  for (const std::string& f : files) {
    if (fs::is_regular_file(dir / "a" / f)) {
      EXPECT_EQ(readFile(dir / "a" / f), readFile(dir / "b" / f)) << f;
    }
  }

  // A generated folder is replaced whole: nothing of the larger generation stays.
  ASSERT_EQ(
      run("generate --seed 6 --count 3 --out " + (dir / "a").string() + " --profile generators")
          .code,
      0);
  EXPECT_FALSE(fs::exists(dir / "a" / "generators-s5-00000.json"));
  EXPECT_TRUE(fs::exists(dir / "a" / "generators-s6-00002.json"));
  EXPECT_FALSE(hasLeftovers(dir));
  fs::remove_all(dir);
}

TEST(CliGenerate, BadArgumentsExitTwoInOneLineAndWriteNothing) {
  const fs::path dir = scratch("bad");
  const fs::path out = dir / "out";
  auto expectTwo = [&](const std::string& args, const std::string& mention) {
    const auto r = run("generate " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_EQ(lineCount(r.out), 1) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(mention), std::string::npos) << args << "\n" << r.out;
    EXPECT_FALSE(fs::exists(out)) << args;
    EXPECT_FALSE(hasLeftovers(dir)) << args;
  };
  const std::string o = " --out " + out.string();
  expectTwo("--seed 1 --count 0" + o, "--count");
  expectTwo("--seed 1 --count -3" + o, "--count");
  expectTwo("--seed 1 --count many" + o, "--count");
  expectTwo("--seed -1 --count 2" + o, "--seed");
  expectTwo("--seed x --count 2" + o, "--seed");
  expectTwo("--count 2" + o, "--seed");
  expectTwo("--seed 1 --count 2", "--out");
  expectTwo("--seed 1 --count 2 --max-size 200" + o, "--max-size");
  expectTwo("--seed 1 --count 2 --max-size 0x100" + o, "--max-size");
  expectTwo("--seed 1 --count 2 --max-size 20000x100" + o, "--max-size");
  expectTwo("--seed 1 --count 2 --profile shiny" + o, "--profile");
  expectTwo("--seed 1 --count 2 --meshes " + (dir / "nowhere").string() + o, "nowhere");
  // --out names a file, or a folder that generate did not write: left alone.
  std::ofstream(dir / "file") << "keep";
  expectTwo("--seed 1 --count 2 --out " + (dir / "file").string(), "file");
  EXPECT_EQ(readFile(dir / "file"), "keep");
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine" / "notes.txt") << "keep";
  expectTwo("--seed 1 --count 2 --out " + (dir / "mine").string(), "generate.json");
  EXPECT_EQ(listing(dir / "mine"), std::vector<std::string>{"notes.txt"});
  fs::remove_all(dir);
}

TEST(CliGenerate, ManyScenesAreQuick) {
  // 2000 scenes of the full distribution (meshes are referenced, not read): well under a
  // few seconds on one core; --count 10000 scales linearly.
  const fs::path dir = scratch("many");
  const auto start = std::chrono::steady_clock::now();
  const auto r = run("generate --seed 77 --count 2000 --out " + (dir / "o").string());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_LT(seconds, 20.0);
  EXPECT_TRUE(fs::exists(dir / "o" / "s77-01999.json"));
  fs::remove_all(dir);
}
