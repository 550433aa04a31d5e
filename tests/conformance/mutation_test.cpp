// The mutation self-test of the harness: each folder under mutations/ holds an original
// fixture and a mutant that differs from it in one thing (an object moved half a pixel, a
// depth offset, a light 1% brighter, normals without the inverse transpose, a triangle
// dropped). The mutant, rendered by a GL backend and compared with the reference of the
// ORIGINAL, must fail in exactly the class mutations.json names and in no other; the
// original rendered by the same backend (the control) must fail in none, so that the
// failure is the mutation's. One GoogleTest per mutation x backend.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "compare/report.h"
#include "fixtures/loader.h"
#include "tests/conformance/conformance_support.h"

namespace fs = std::filesystem;
using namespace rc;
using namespace rc::conformance;

namespace {

const fs::path kMutations = fs::path(RC_SOURCE_DIR) / "tests" / "conformance" / "mutations";

std::string identifier(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

std::string joined(const std::set<std::string>& s) {
  std::string out;
  for (const std::string& x : s) out += (out.empty() ? "" : ", ") + x;
  return out.empty() ? "none" : out;
}

class MutationTest : public testing::Test {
 public:
  MutationTest(std::string name, std::string cls, std::string backend)
      : name_(std::move(name)), cls_(std::move(cls)), backend_(std::move(backend)) {}

  void TestBody() override {
    const fs::path original_file = kMutations / name_ / "original.json";
    const fs::path mutant_file = kMutations / name_ / "mutant.json";
    const BackendRender control = renderWithBackend(original_file, backend_);
    if (control.unavailable) {
      if (glRequired()) FAIL() << backend_ << " cannot start: " << control.error;
      GTEST_SKIP() << backend_ << " cannot start on this machine: " << control.error;
    }
    ASSERT_TRUE(control.frame) << backend_ << " failed on " << original_file << ": "
                               << control.error;
    const BackendRender mutant = renderWithBackend(mutant_file, backend_);
    ASSERT_TRUE(mutant.frame) << backend_ << " failed on " << mutant_file << ": " << mutant.error;
    const Scene original = loadScene(original_file);
    const Frame ref = renderReference(original_file);

    const std::string test = testing::UnitTest::GetInstance()->current_test_info()->name();
    PairResult c =
        compareFrames(ref, *control.frame, ref, tolerancesFor(original, ref, *control.frame));
    c.fixture = original.name;
    c.expected = "ref";
    c.actual = backend_;
    if (!failingClasses(c).empty()) {
      ADD_FAILURE() << "the unmutated fixture already fails, so the mutant proves nothing: "
                    << describe(c) << "\nimages and report: "
                    << writeArtifacts(test + "__control", ref, *control.frame, ref, c).string();
    }

    PairResult m =
        compareFrames(ref, *mutant.frame, ref, tolerancesFor(original, ref, *mutant.frame));
    m.fixture = original.name + " (mutant)";
    m.expected = "ref";
    m.actual = backend_;
    const std::set<std::string> failing = failingClasses(m);
    if (failing != std::set<std::string>{cls_}) {
      ADD_FAILURE() << "the mutant must fail in " << cls_ << " only, fails in " << joined(failing)
                    << ": " << describe(m) << "\nimages and report: "
                    << writeArtifacts(test, ref, *mutant.frame, ref, m).string();
    }
  }

 private:
  std::string name_;
  std::string cls_;
  std::string backend_;
};

void registerMutations() {
  std::ifstream in(kMutations / "mutations.json");
  const auto doc = nlohmann::json::parse(in);
  for (const auto& m : doc.at("mutations")) {
    const std::string name = m.at("name").get<std::string>();
    const std::string cls = m.at("class").get<std::string>();
    for (const std::string& backend : backends()) {
      const std::string test = identifier(name) + "__" + identifier(backend);
      testing::RegisterTest("mutation", test.c_str(), nullptr, nullptr, __FILE__, __LINE__,
                            [name, cls, backend]() -> testing::Test* {
                              return new MutationTest(name, cls, backend);
                            });
    }
  }
}

}  // namespace

// Every folder has its manifest entry and every entry its folder, with a known class.
TEST(MutationManifest, MatchesTheFolders) {
  std::ifstream in(kMutations / "mutations.json");
  const auto doc = nlohmann::json::parse(in);
  std::set<std::string> listed;
  for (const auto& m : doc.at("mutations")) {
    const std::string name = m.at("name").get<std::string>();
    listed.insert(name);
    const std::string cls = m.at("class").get<std::string>();
    EXPECT_TRUE(cls == "visibility" || cls == "depth" || cls == "shading") << name << ": " << cls;
    EXPECT_TRUE(fs::exists(kMutations / name / "original.json")) << name;
    EXPECT_TRUE(fs::exists(kMutations / name / "mutant.json")) << name;
  }
  std::set<std::string> folders;
  for (const auto& entry : fs::directory_iterator(kMutations))
    if (entry.is_directory()) folders.insert(entry.path().filename().string());
  EXPECT_EQ(listed, folders);
}

int main(int argc, char** argv) {
  try {
    testing::InitGoogleTest(&argc, argv);
    registerMutations();
    return RUN_ALL_TESTS();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cannot register the tests: %s\n", e.what());
    return 1;
  }
}
