// The fragment loop's specialised forms (reference/fragment_loop.cpp: one stored colour for a
// flat untextured triangle, Gouraud written out with the triangle's constants, untextured
// Phong eight fragments at a time in vector lanes) against the scalar definition they stand
// for (fragmentColor() and writeColor(), ReferenceOptions::fragment_definition_only), bit for
// bit in every plane of the frame, uncertainty channels included: on the feature scenes, the
// benchmark scenes at a small size, random scenes of every profile and the catalog's shading
// and blending folders, in each depth and colour format they use.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "fixtures/loader.h"
#include "reference/reference_renderer.h"
#include "tests/reference/corpus.h"
#include "tests/reference/test_scenes.h"
#include "tests/support/random_fixtures.h"

namespace rc {
namespace {

// Renders `scene` both ways under each option set; the first difference as a message.
::testing::AssertionResult sameBothWays(const Scene& scene) {
  for (const bool uncertainty : {true, false}) {
    for (const int bits : {8, 4}) {
      ReferenceOptions fast;
      fast.subpixel_bits = bits;
      fast.uncertainty = uncertainty;
      ReferenceOptions definition = fast;
      definition.fragment_definition_only = true;
      const Frame a = renderReference(scene, fast);
      const Frame b = renderReference(scene, definition);
      if (test::frameBytes(a) != test::frameBytes(b)) {
        std::size_t pixel = 0;
        while (pixel < a.pixelCount() && a.color[4 * pixel] == b.color[4 * pixel] &&
               a.color[4 * pixel + 1] == b.color[4 * pixel + 1] &&
               a.color[4 * pixel + 2] == b.color[4 * pixel + 2] &&
               a.color[4 * pixel + 3] == b.color[4 * pixel + 3])
          ++pixel;
        return ::testing::AssertionFailure()
               << "frames differ (uncertainty " << uncertainty << ", subpixel bits " << bits
               << "); first colour difference at pixel index " << pixel;
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Scenes where the fast forms are taken: every shading mode over whole layers and small
// triangles, thin slivers (Gouraud's shade_reach loop), both colour formats, three depth
// formats.
TEST(FragmentLoop, FastFormsEqualTheDefinitionOnBuiltScenes) {
  for (const test::NamedScene& s : test::featureScenes())
    EXPECT_TRUE(sameBothWays(s.scene)) << s.name;
  for (const Shading shading : {Shading::Flat, Shading::Gouraud, Shading::Phong}) {
    for (const ColorFormat color : {ColorFormat::RGBA8, ColorFormat::RGBA32F}) {
      for (const DepthFormat depth : {DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F}) {
        Scene layers = test::layersScene(shading, 64, 3);
        layers.state.color_format = color;
        layers.state.depth_format = depth;
        EXPECT_TRUE(sameBothWays(layers))
            << "layers " << toString(shading) << " " << toString(color) << " " << toString(depth);
        Scene soup = test::smallTrianglesScene(64, 400);
        soup.state.shading = shading;
        soup.state.color_format = color;
        soup.state.depth_format = depth;
        EXPECT_TRUE(sameBothWays(soup))
            << "soup " << toString(shading) << " " << toString(color) << " " << toString(depth);
      }
    }
  }
}

TEST(FragmentLoop, FastFormsEqualTheDefinitionOnRandomAndCatalogScenes) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(RC_BINARY_DIR) / "tests" / "reference" / "fragment_loop_random";
  std::vector<fs::path> files = test::writeRandomProfiles(dir, 20261204, 8);
  ASSERT_GE(files.size(), 32u);
  const fs::path catalog = fs::path(RC_SOURCE_DIR) / "fixtures" / "scenes";
  for (const char* folder : {"shading", "lighting", "transparency", "textures", "msaa"}) {
    if (!fs::is_directory(catalog / folder)) continue;
    for (const fs::path& f : test::fixtureFiles(catalog / folder)) files.push_back(f);
  }
  for (const fs::path& f : files) EXPECT_TRUE(sameBothWays(loadScene(f))) << f.string();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rc
