// The mutation self-test of the harness: mutations/mutations.json pairs an original
// fixture with a mutant fixture that differs in one thing (an object moved half a pixel, a
// depth offset, a light 1% brighter, normals without the inverse transpose, a triangle
// dropped) or with a GL-side fault (RASTERCHECK_GL_FAULT, test-only; skipped where the
// GL backend does not read it). The mutant, rendered by a GL backend and compared with
// the reference of the ORIGINAL, must fail in exactly the class the entry names and in no
// other; the original rendered by the same backend (the control) must fail in none, so
// that the failure is the mutation's. One GoogleTest per mutation x backend.
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
const char* const kFaultVariable = "RASTERCHECK_GL_FAULT";

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

// One entry of mutations.json: a mutant fixture, or a fault injected into GL.
struct Mutation {
  std::string name;
  std::string cls;
  fs::path original;
  fs::path mutant;       // empty for a GL fault
  std::string gl_fault;  // RASTERCHECK_GL_FAULT value, empty for a mutant fixture
};

std::vector<Mutation> readManifest() {
  std::ifstream in(kMutations / "mutations.json");
  const auto doc = nlohmann::json::parse(in);
  std::vector<Mutation> out;
  for (const auto& m : doc.at("mutations")) {
    Mutation x;
    x.name = m.at("name").get<std::string>();
    x.cls = m.at("class").get<std::string>();
    x.original = kMutations / m.at("original").get<std::string>();
    if (m.contains("mutant")) x.mutant = kMutations / m.at("mutant").get<std::string>();
    if (m.contains("gl_fault")) x.gl_fault = m.at("gl_fault").get<std::string>();
    out.push_back(x);
  }
  return out;
}

class MutationTest : public testing::Test {
 public:
  MutationTest(Mutation mutation, std::string backend)
      : m_(std::move(mutation)), backend_(std::move(backend)) {}

  void TestBody() override {
    const BackendRender control = renderWithBackend(m_.original, backend_);
    if (control.unavailable) {
      if (glRequired()) FAIL() << backend_ << " cannot start: " << control.error;
      GTEST_SKIP() << backend_ << " cannot start on this machine: " << control.error;
    }
    ASSERT_TRUE(control.frame) << backend_ << " failed on " << m_.original << ": " << control.error;
    const BackendRender mutant = m_.gl_fault.empty()
                                     ? renderWithBackend(m_.mutant, backend_)
                                     : renderWithBackend(m_.original, backend_, m_.gl_fault);
    ASSERT_TRUE(mutant.frame) << backend_ << " failed on the mutant: " << mutant.error;
    // The test-only fault hook must have run: a backend that ignored the variable would
    // render the original and the self-test would prove nothing.
    if (!m_.gl_fault.empty()) {
      ASSERT_TRUE(mutant.frame->meta.contains("fault_injected"))
          << backend_ << " ignored " << kFaultVariable << "=" << m_.gl_fault
          << " (no fault_injected in frame.json)";
    }
    const Scene original = loadScene(m_.original);
    const Frame ref = renderReference(m_.original);

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

    PairResult r =
        compareFrames(ref, *mutant.frame, ref, tolerancesFor(original, ref, *mutant.frame));
    r.fixture = original.name + " (" + m_.name + ")";
    r.expected = "ref";
    r.actual = backend_;
    const std::set<std::string> failing = failingClasses(r);
    if (failing != std::set<std::string>{m_.cls}) {
      ADD_FAILURE() << "the mutant must fail in " << m_.cls << " only, fails in " << joined(failing)
                    << ": " << describe(r) << "\nimages and report: "
                    << writeArtifacts(test, ref, *mutant.frame, ref, r).string();
    }
  }

 private:
  Mutation m_;
  std::string backend_;
};

void registerMutations() {
  for (const Mutation& m : readManifest()) {
    for (const std::string& backend : backends()) {
      const std::string test = identifier(m.name) + "__" + identifier(backend);
      testing::RegisterTest(
          "mutation", test.c_str(), nullptr, nullptr, __FILE__, __LINE__,
          [m, backend]() -> testing::Test* { return new MutationTest(m, backend); });
    }
  }
}

}  // namespace

// Every entry names existing files, a known class and exactly one of mutant / gl_fault;
// every folder is used by some entry.
TEST(MutationManifest, MatchesTheFolders) {
  std::set<std::string> used;
  for (const Mutation& m : readManifest()) {
    EXPECT_TRUE(m.cls == "visibility" || m.cls == "depth" || m.cls == "shading")
        << m.name << ": " << m.cls;
    EXPECT_TRUE(fs::exists(m.original)) << m.name << ": " << m.original;
    EXPECT_NE(m.mutant.empty(), m.gl_fault.empty()) << m.name << ": mutant or gl_fault";
    if (!m.mutant.empty()) {
      EXPECT_TRUE(fs::exists(m.mutant)) << m.name << ": " << m.mutant;
    }
    used.insert(m.original.parent_path().filename().string());
  }
  std::set<std::string> folders;
  for (const auto& entry : fs::directory_iterator(kMutations))
    if (entry.is_directory()) folders.insert(entry.path().filename().string());
  EXPECT_EQ(used, folders);
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
