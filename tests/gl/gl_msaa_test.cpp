// Multisampling on real drivers: the msaa catalog fixtures rendered by the driver under
// test and by the reference at the driver's own sample positions (frame.json) must agree
// sample by sample (no hard coverage difference, depth and resolved colour within
// tolerance); a driver with fewer samples than asked (softpipe: GL_MAX_SAMPLES 1) must say
// "not supported" rather than fail or draw single-sampled.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "fixtures/loader.h"
#include "fixtures/multisample.h"
#include "reference/reference_renderer.h"
#include "tests/gl/gl_test_util.h"

namespace rc::gltest {
namespace {
namespace fs = std::filesystem;

class GlMultisample : public GlTest {};

// softpipe has GL_MAX_SAMPLES 1.
bool expectNoMsaa() { return specText().find("softpipe") != std::string::npos; }

TEST_F(GlMultisample, CatalogFixturesAgreeWithTheReferenceOrAreNotSupported) {
  for (const char* name :
       {"edge_slopes.json", "shared_fan.json", "interpenetrating.json", "zfight_4x.json"}) {
    SCOPED_TRACE(name);
    const Scene scene = loadScene(fs::path(RC_SOURCE_DIR) / "fixtures/scenes/msaa" / name);
    Frame gl;
    try {
      gl = render(scene);
    } catch (const NotSupportedError& e) {
      EXPECT_TRUE(expectNoMsaa()) << specText() << " should multisample: " << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("not supported: ", 0), 0u) << e.what();
      continue;
    }
    ASSERT_FALSE(expectNoMsaa()) << specText() << " rendered 4 samples; GL_MAX_SAMPLES is 1";
    ASSERT_EQ(gl.samples, 4);
    EXPECT_GE(gl.meta["max_samples"].get<int>(), 4);
    const std::vector<glm::dvec2> positions = samplePositionsFromMeta(gl.meta);
    ASSERT_EQ(positions.size(), 4u);
    ReferenceOptions options;
    options.sample_positions = positions;
    Frame ref = renderReference(scene, options);
    for (Frame* f : {&ref, &gl}) f->meta["fixture"] = scene.name;
    ref.meta["backend"] = "ref";
    gl.meta["backend"] = specText();
    const PairResult r = compareFrames(ref, gl, ref, tolerancesForFrames(ref, gl));
    EXPECT_EQ(r.visibility.hard, 0u);
    EXPECT_EQ(r.depth.status, Status::Pass) << r.depth.max_steps;
    EXPECT_EQ(r.shading.status, Status::Pass) << r.shading.max_abs;
    EXPECT_EQ(r.status, Status::Pass);
    // Antialiased: some pixels are partly covered (the resolve really averaged samples).
    int partial = 0;
    for (float c : gl.coverage) partial += c < 4.0f ? 1 : 0;
    EXPECT_GT(partial, 0);
  }
}

// The measured facts of DESIGN.md: llvmpipe and zink use the standard 4x pattern.
TEST_F(GlMultisample, ReportsTheStandardFourSamplePattern) {
  Scene s = orthoScene(4, 4);
  s.state.samples = 4;
  Frame f;
  try {
    f = render(s);
  } catch (const NotSupportedError&) {
    EXPECT_TRUE(expectNoMsaa());
    return;
  }
  if (specText().find("llvmpipe") == std::string::npos &&
      specText().find("zink") == std::string::npos)
    GTEST_SKIP() << "positions measured on llvmpipe and zink only";
  EXPECT_EQ(samplePositionsFromMeta(f.meta), standardSamplePositions(4));
}

}  // namespace
}  // namespace rc::gltest
