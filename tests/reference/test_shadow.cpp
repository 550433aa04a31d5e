// Shadow lookups and multi-pass scenes in the reference (reference/shadow.h,
// reference/multipass.h): a floor under a square blocker lit straight down through an
// orthographic map, whose shadow and lit regions have analytic colours; the compare
// function's direction; the range of results another implementation may give (zero inside
// the regions, the whole light at the shadow's border); percentage-closer filtering between
// the two; a colour target sampled back exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include <nlohmann/json.hpp>

#include "fixtures/loader.h"
#include "fixtures/scene_logic.h"
#include "reference/multipass.h"
#include "reference/reference_renderer.h"
#include "reference/shadow.h"

namespace rc {
namespace {

using nlohmann::json;

// A 64x64 view straight down onto a 4x4 floor (y = 0, kd 0.5, ambient 0.1 of light 1) with
// a 1x1 blocker at y = 1 over x, z in [-0.5, 0.5]; a directional light straight down whose
// 64x64 d24 orthographic map covers the floor exactly. The camera sees x in [-2, 2].
json blockerScene(const std::string& compare = "lequal", const std::string& filter = "nearest") {
  const json floor_quad = {{"positions", {{-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}}},
                           {"normals", {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}}},
                           {"triangles", {{0, 1, 2}, {0, 2, 3}}}};
  const json blocker = {
      {"positions", {{-0.5, 1, 0.5}, {0.5, 1, 0.5}, {0.5, 1, -0.5}, {-0.5, 1, -0.5}}},
      {"normals", {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}}},
      {"triangles", {{0, 1, 2}, {0, 2, 3}}}};
  const json down = {{"projection", "orthographic"},
                     {"eye", {0, 5, 0}},
                     {"target", {0, 0, 0}},
                     {"up", {0, 0, -1}},
                     {"bounds", {-2, 2, -2, 2}},
                     {"near", 1},
                     {"far", 10}};
  const json lookup = {{"map", "sun"}, {"compare", compare}, {"filter", filter}, {"bias", 0.001}};
  return {
      {"format", kSceneFormat},
      {"name", "shadow/blocker"},
      {"image", {{"width", 64}, {"height", 64}}},
      {"camera", down},
      {"ambient_light", {1, 1, 1}},
      {"lights", {{{"type", "directional"}, {"direction", {0, -1, 0}}, {"shadow_map", "sun"}}}},
      {"targets", {{"sun", {{"width", 64}, {"height", 64}, {"format", "d24"}}}}},
      {"materials",
       {{"floor", {{"ambient", {0.1, 0.1, 0.1}}, {"diffuse", {0.5, 0.5, 0.5}}, {"shadow", lookup}}},
        {"lid", {{"ambient", {0.1, 0.1, 0.1}}, {"diffuse", {0.2, 0.2, 0.2}}}}}},
      {"objects",
       {{{"name", "floor"}, {"material", "floor"}, {"mesh", floor_quad}},
        {{"name", "blocker"}, {"material", "lid"}, {"mesh", blocker}}}},
      {"passes", {{{"target", "sun"}, {"camera", down}}, {{"target", "frame"}}}},
      {"state", {{"shading", "phong"}}}};
}

Scene load(const json& doc) { return loadScene(doc, "blocker.json"); }

// Image pixel (x, y) of the 64x64 view covers world x in [-2 + x/16, ...], z likewise.
float red(const Frame& f, int x, int y) { return f.color[f.index(x, y) * 4]; }

TEST(Shadow, BlockerShadowsTheFloorBelowItAndNothingElse) {
  const Frame f = renderReference(load(blockerScene()));
  ASSERT_EQ(f.passes.size(), 1u);
  EXPECT_EQ(f.passes[0].width, 64);
  // Floor far from the blocker: ambient 0.1 + diffuse 0.5; the blocker itself 0.1 + 0.2.
  EXPECT_FLOAT_EQ(red(f, 4, 4), 0.6f);
  EXPECT_FLOAT_EQ(red(f, 60, 60), 0.6f);
  EXPECT_FLOAT_EQ(red(f, 32, 32), 0.3f);
  // The blocker's own pixels hide the floor's shadow straight below: look at a tilted view.
  json doc = blockerScene();
  doc["camera"] = {{"eye", {0, 6, 4}}, {"target", {0, 0, 0}}, {"fovy_deg", 50}};
  doc["objects"][1]["material"] = "lid";
  const Frame tilted = renderReference(load(doc));
  // Somewhere the floor is in shadow (ambient alone, 0.1) and lit (0.6).
  int shadowed = 0;
  int lit = 0;
  for (std::size_t i = 0; i < tilted.pixelCount(); ++i) {
    if (tilted.id[i] == 0) continue;
    shadowed += tilted.color[i * 4] == 0.1f;
    lit += tilted.color[i * 4] == 0.6f;
  }
  EXPECT_GT(shadowed, 50);
  EXPECT_GT(lit, 500);
}

// GREATER is lit exactly where LEQUAL is not (the blocker's depth is below the floor's in
// the map: only shadowed floor passes r > D); ALWAYS lights everything, NEVER nothing.
TEST(Shadow, CompareFunctionDecidesWhatIsLit) {
  json doc = blockerScene("greater");
  doc["camera"] = {{"eye", {0, 6, 4}}, {"target", {0, 0, 0}}, {"fovy_deg", 50}};
  json le = doc;
  le["materials"]["floor"]["shadow"]["compare"] = "lequal";
  const Frame g = renderReference(load(doc));
  const Frame l = renderReference(load(le));
  int flipped = 0;
  for (std::size_t i = 0; i < g.pixelCount(); ++i) {
    if (g.id[i] == 0 || g.id[i] > 2) continue;  // floor triangles are ids 1 and 2
    const float a = g.color[i * 4];
    const float b = l.color[i * 4];
    EXPECT_TRUE((a == 0.1f && b == 0.6f) || (a == 0.6f && b == 0.1f)) << i << " " << a << " " << b;
    flipped += a != b;
  }
  EXPECT_GT(flipped, 1000);
  for (const char* fixed : {"always", "never"}) {
    json d = doc;
    d["materials"]["floor"]["shadow"]["compare"] = fixed;
    const Frame f = renderReference(load(d));
    const float want = std::string(fixed) == "always" ? 0.6f : 0.1f;
    for (std::size_t i = 0; i < f.pixelCount(); ++i) {
      if (f.id[i] != 1 && f.id[i] != 2) continue;
      EXPECT_EQ(f.color[i * 4], want) << fixed << " " << i;
    }
  }
}

// The range another implementation's lookup may give: nothing inside the shadow or the lit
// floor, the whole light (0.5 of red, 127.5 units) at the shadow's border. The blocker is
// moved by half a map texel so that its edges cross texel centres (on texel boundaries the
// map's texels are certain, and so is every lookup that is not within its own error of
// one).
TEST(Shadow, UncertaintyIsZeroInsideTheRegionsAndTheWholeLightAtTheBorder) {
  json doc = blockerScene();
  doc["camera"] = {{"eye", {0, 6, 4}}, {"target", {0, 0, 0}}, {"fovy_deg", 50}};
  for (auto& p : doc["objects"][1]["mesh"]["positions"]) {
    p[0] = p[0].get<double>() + 1.0 / 8.0;  // half a texel of the 4-unit, 16-texel map
    p[2] = p[2].get<double>() + 1.0 / 8.0;
  }
  // A map coarser than the view's pixels on the floor: each change of the lookup's result
  // passes through the texels along the blocker's edge.
  doc["targets"]["sun"]["width"] = doc["targets"]["sun"]["height"] = 16;
  const Frame f = renderReference(load(doc));
  ASSERT_TRUE(f.hasUncertainty());
  int border = 0;
  for (int y = 1; y + 1 < f.height; ++y) {
    for (int x = 1; x + 1 < f.width; ++x) {
      const std::size_t i = f.index(x, y);
      if (f.id[i] != 1 && f.id[i] != 2) continue;
      // Two floor pixels side by side on either side of the shadow's edge: one of them
      // is left to the implementation.
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const std::size_t j = f.index(x + dx, y + dy);
        if ((f.id[j] != 1 && f.id[j] != 2) || f.color[j * 4] == f.color[i * 4]) continue;
        ++border;
        EXPECT_GE(std::max(f.normal_reach[i], f.normal_reach[j]), 127.0f) << x << "," << y;
      }
      bool calm = true;  // 3 px from any change: inside a region
      for (int dy = -3; dy <= 3 && calm; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
          const int nx = x + dx;
          const int ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= f.width || ny >= f.height) continue;
          const std::size_t j = f.index(nx, ny);
          if (f.id[j] != f.id[i] || f.color[j * 4] != f.color[i * 4]) calm = false;
        }
      if (calm) {
        EXPECT_EQ(f.normal_reach[i], 0.0f) << x << "," << y;
      }
    }
  }
  EXPECT_GT(border, 20);
}

// A point whose centre lies just outside the map (the blocker in polygon mode point, one
// corner a third of a texel past the map's right border, 4 px points): GL discards it, a
// driver that clips points as squares draws its part inside (llvmpipe: campaign s20261339
// scene 00030, 258 units of shadow on the floor). The map's range is open there, any depth,
// and nowhere else: the columns it may reach, the texels around its corner.
TEST(Shadow, APointOnlyAnotherDriverDrawsOpensTheMapsRangeWhereItMayReach) {
  json doc = blockerScene();
  doc["objects"][1]["state"] = {{"polygon_mode", "point"}};
  doc["state"]["point_size"] = 4;
  // x in [1.52, 2.02]: the corners at x = 2.02 map to texel x 64.32 of 64, the others inside.
  for (auto& p : doc["objects"][1]["mesh"]["positions"])
    p[0] = p[0].get<double>() < 0.0 ? 1.52 : 2.02;
  const ref::PassOutputs out = ref::renderPasses(load(doc), ReferenceOptions{});
  const std::shared_ptr<const ShadowMapData>& map = out.frame_scene.materials[0].shadow->data;
  ASSERT_TRUE(map);
  ASSERT_EQ(map->lo.size(), static_cast<std::size_t>(64 * 64));
  int open = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const std::size_t k = static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x);
      const bool any = map->lo[k] == 0.0 && map->hi[k] == 1.0;
      if (x < 60) {
        EXPECT_FALSE(any) << x << "," << y;  // the points inside are drawn, their range tight
      }
      open += any ? 1 : 0;
    }
  }
  // Two corners, each a square of 4 px (+1 of reach) around a centre 0.32 px outside.
  EXPECT_GE(open, 2 * 2 * 4);
  EXPECT_LE(open, 2 * 4 * 11);
}

// Linear lookups give values between lit and shadowed at the border (the reference's
// bilinear weights), inside the range it allows.
TEST(Shadow, PercentageCloserFilteringBlendsAtTheBorder) {
  json doc = blockerScene("lequal", "linear");
  doc["camera"] = {{"eye", {0, 6, 4}}, {"target", {0, 0, 0}}, {"fovy_deg", 50}};
  doc["targets"]["sun"]["width"] = doc["targets"]["sun"]["height"] = 16;
  const Frame f = renderReference(load(doc));
  int between = 0;
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    if (f.id[i] != 1 && f.id[i] != 2) continue;
    const float r = f.color[i * 4];
    EXPECT_GE(r, 0.1f - 1e-6f);
    EXPECT_LE(r, 0.6f + 1e-6f);
    if (r > 0.11f && r < 0.59f) {
      ++between;
      EXPECT_GE(f.normal_reach[i], 255.0f * std::max(r - 0.1f, 0.6f - r) - 1e-3f);
    }
  }
  EXPECT_GT(between, 20);
}

// shadowFactor at points in front of, inside and behind the map's camera.
TEST(Shadow, LookupBehindTheMapsCameraIsLit) {
  const Scene scene = load(blockerScene());
  ShadowLookup lookup = *scene.materials[0].shadow;
  auto map = std::make_shared<ShadowMapData>();
  map->width = map->height = 2;
  map->format = DepthFormat::D24;
  map->depth = {0.0, 0.0, 0.0, 0.0};  // everything occluded
  map->matrix = shadowMatrix(scene, "sun");
  lookup.data = map;
  EXPECT_EQ(ref::shadowFactor(lookup, {0, 0, 0}), 0.0);
  // The orthographic map has w = 1 everywhere; a perspective one is tested by the catalog.
  map->depth = {1.0, 1.0, 1.0, 1.0};
  EXPECT_EQ(ref::shadowFactor(lookup, {0, 0, 0}), 1.0);
  // Clamp to edge: outside the map the edge texel decides.
  map->depth = {1.0, 0.0, 1.0, 0.0};  // right column occluded
  EXPECT_EQ(ref::shadowFactor(lookup, {50, 0, 0}), 0.0);
  EXPECT_EQ(ref::shadowFactor(lookup, {-50, 0, 0}), 1.0);
}

// A colour target comes back as the texture the frame pass samples: a quad showing the
// target with nearest filtering at texel centres reproduces the target's 8-bit colours.
TEST(MultiPassReference, ColourTargetIsSampledAsDrawn) {
  const json quad = {{"positions", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}},
                     {"uvs", {{0, 0}, {1, 0}, {1, 1}, {0, 1}}},
                     {"triangles", {{0, 1, 2}, {0, 2, 3}}}};
  const json ortho = {
      {"projection", "orthographic"}, {"eye", {0, 0, 5}}, {"bounds", {-1, 1, -1, 1}}};
  const json doc = {
      {"format", kSceneFormat},
      {"image", {{"width", 16}, {"height", 16}}},
      {"camera", ortho},
      {"targets", {{"t", {{"width", 16}, {"height", 16}, {"format", "rgba8"}}}}},
      {"ambient_light", {1, 1, 1}},
      {"materials",
       {{"paint", {{"ambient", {0.3, 0.6, 0.9}}, {"diffuse", {0, 0, 0}}}},
        {"show", {{"ambient", {1, 1, 1}}, {"diffuse", {0, 0, 0}}, {"texture", "target:t"}}}}},
      {"objects",
       {{{"name", "tri"},
         {"material", "paint"},
         {"mesh",
          {{"positions", {{-1, -1, 0}, {1, -1, 0}, {-1, 1, 0}}}, {"triangles", {{0, 1, 2}}}}}},
        {{"name", "quad"}, {"material", "show"}, {"mesh", quad}}}},
      {"passes",
       {{{"target", "t"}, {"objects", {"tri"}}, {"state", {{"color_format", "rgba8"}}}},
        {{"target", "frame"}, {"objects", {"quad"}}}}},
      {"state", {{"shading", "phong"}, {"color_format", "rgba8"}}}};
  const Frame f = renderReference(loadScene(doc, "rtt.json"));
  ASSERT_EQ(f.passes.size(), 1u);
  const Frame& t = f.passes[0];
  // RGB: the frame's alpha is the material's opacity, not the texel's.
  for (std::size_t i = 0; i < f.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(f.color[i * 4 + c], t.color[i * 4 + c]) << i;
}

}  // namespace
}  // namespace rc
