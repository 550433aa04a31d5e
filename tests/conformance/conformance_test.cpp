// The conformance suite: every catalog fixture x every GL backend, compared with the
// reference, one GoogleTest test per pair (suite = topic folder, name = fixture and
// backend), so ctest -R / -L and GTEST_TOTAL_SHARDS/GTEST_SHARD_INDEX work as for any
// GoogleTest suite. A pair passes when exactly the classes listed for it in
// expectations.json fail: an unexpected failure and an unexpected pass both fail.
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/report_support.h"
#include "compare/report.h"
#include "fixtures/catalog.h"
#include "fixtures/loader.h"
#include "fixtures/scene_writer.h"
#include "tests/conformance/conformance_support.h"

namespace fs = std::filesystem;
using namespace rc;
using namespace rc::conformance;

namespace {

std::string identifier(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

class ConformancePair : public ::testing::Test {
 public:
  ConformancePair(fs::path file, std::string backend)
      : file_(std::move(file)), backend_(std::move(backend)) {}

  void TestBody() override {
    const BackendRender gl = renderWithBackend(file_, backend_);
    if (gl.unavailable) {
      if (glRequired()) FAIL() << backend_ << " cannot start: " << gl.error;
      GTEST_SKIP() << backend_ << " cannot start on this machine: " << gl.error;
    }
    // The driver ran and cannot render what the fixture asks (softpipe and 4 samples): a
    // skip, what junit.xml reports for a not_supported row, also with RASTERCHECK_REQUIRE_GL.
    if (!gl.frame) {
      if (const auto reason = notSupportedReason(gl.error))
        GTEST_SKIP() << "not supported: " << *reason;
    }
    const Scene scene = loadScene(file_);
    ASSERT_TRUE(gl.frame) << backend_ << " failed on " << scene.name << " (exit " << gl.exit_code
                          << "): " << gl.error;
    Frame ref = renderReference(file_);
    resampleReference(ref, *gl.frame, file_, ReferenceOptions{});  // the driver's positions

    PairResult result = compareFrames(ref, *gl.frame, ref, tolerancesFor(scene, ref, *gl.frame));
    result.fixture = scene.name;
    result.expected = "ref";
    result.actual = backend_;
    const std::set<std::string> failing = failingClasses(result);
    // Classes known to fail here may fail; those of strict entries (one fixture named
    // exactly) must (an expected failure that went away is news too).
    PairContext pair;
    pair.fixture = scene.name;
    pair.backend = backend_;
    pair.driver_version = gl.frame->meta.value("gl_version", "");
    pair.state = stateJson(scene.state);
    pair.tags = scene.tags;
    std::set<std::string> allowed;
    std::set<std::string> required;
    std::string reasons;
    for (const Expectation& e : expectations().parsed.entries) {
      if (!covers(e, pair)) continue;
      allowed.insert(e.cls);
      if (e.strict) required.insert(e.cls);
      reasons += fmt::format("\n  {} expected to fail ({}): {}", e.cls, e.id, e.reason);
    }
    bool ok = true;
    for (const std::string& c : failing) ok = ok && allowed.count(c) > 0;
    for (const std::string& c : required) ok = ok && failing.count(c) > 0;
    if (!ok) {
      const fs::path artifacts =
          writeArtifacts(::testing::UnitTest::GetInstance()->current_test_info()->name(), ref,
                         *gl.frame, ref, result);
      for (const std::string& c : failing) {
        EXPECT_TRUE(allowed.count(c)) << "unexpected failure: " << describe(result);
      }
      for (const std::string& c : required) {
        EXPECT_TRUE(failing.count(c))
            << "unexpected pass of " << c
            << " (remove it from fixtures/expectations.json): " << describe(result) << reasons;
      }
      ADD_FAILURE() << "images and report: " << artifacts.string();
    }
    RecordProperty("verdict", toString(result.status));
  }

 private:
  fs::path file_;
  std::string backend_;
};

void registerCatalog() {
  for (const fs::path& file : findFixtures({catalogDir()})) {
    // Registration only reads the name, so that listing tests stays cheap; the test
    // body loads and validates the whole fixture.
    std::ifstream in(file);
    const auto doc = nlohmann::json::parse(in, nullptr, false);
    std::string name = file.stem().string();
    if (doc.is_object() && doc.contains("name") && doc["name"].is_string())
      name = doc["name"].get<std::string>();
    const std::size_t slash = name.find('/');
    const std::string topic = slash == std::string::npos ? "misc" : name.substr(0, slash);
    const std::string rest = slash == std::string::npos ? name : name.substr(slash + 1);
    for (const std::string& backend : backends()) {
      const std::string suite = identifier(topic);
      const std::string test = identifier(rest) + "__" + identifier(backend);
      // No value parameter: it would end up in the test's name as "# GetParam() = ...".
      ::testing::RegisterTest(
          suite.c_str(), test.c_str(), nullptr, nullptr, __FILE__, __LINE__,
          [file, backend]() -> ::testing::Test* { return new ConformancePair(file, backend); });
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    ::testing::InitGoogleTest(&argc, argv);
    registerCatalog();
    return RUN_ALL_TESTS();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cannot register the tests: %s\n", e.what());
    return 1;
  }
}
