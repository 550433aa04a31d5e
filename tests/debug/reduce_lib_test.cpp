// The debug library's delta debugging (debug/reduce.h) called directly: ddmin on analytic
// predicates (the answer is known), scene subsetting, and the whole reduction with a
// predicate that needs one triangle, one light and a minimum image size.
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "debug/reduce.h"
#include "tests/debug/debug_lib_scenes.h"

namespace rc {
namespace {

using Items = std::vector<std::uint32_t>;

Items range(std::uint32_t n) {
  Items v(n);
  for (std::uint32_t k = 0; k < n; ++k) v[k] = k;
  return v;
}

bool contains(const Items& v, std::uint32_t x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

TEST(Ddmin, FindsTheThreeElementsAFailureNeeds) {
  int calls = 0;
  const auto fails = [&](const Items& s) {
    ++calls;
    return contains(s, 17) && contains(s, 42) && contains(s, 73);
  };
  EXPECT_EQ(ddmin(range(100), fails), (Items{17, 42, 73}));
  EXPECT_LT(calls, 400);  // ddmin's worst case is quadratic; three elements cost far less
}

TEST(Ddmin, ASingleCauseIsFoundByHalving) {
  int calls = 0;
  const Items got = ddmin(range(1024), [&](const Items& s) {
    ++calls;
    return contains(s, 700);
  });
  EXPECT_EQ(got, Items{700});
  EXPECT_LE(calls, 2 * 10);  // at most two tests per halving of 1024
}

TEST(Ddmin, TheResultIsOneMinimal) {
  // Fails with 5 alone, or with both 1 and 2: either answer is 1-minimal.
  const auto fails = [](const Items& s) {
    return contains(s, 5) || (contains(s, 1) && contains(s, 2));
  };
  const Items got = ddmin(range(12), fails);
  ASSERT_TRUE(fails(got));
  for (std::size_t k = 0; k < got.size(); ++k) {
    Items less = got;
    less.erase(less.begin() + static_cast<std::ptrdiff_t>(k));
    EXPECT_FALSE(fails(less)) << "removing " << got[k] << " still fails";
  }
  EXPECT_TRUE(got == Items{5} || got == (Items{1, 2})) << got.size();
}

TEST(Ddmin, StopsWhenToldAndKeepsAFailingSet) {
  int calls = 0;
  const auto fails = [&](const Items& s) {
    ++calls;
    return contains(s, 3) && contains(s, 60);
  };
  const Items got = ddmin(range(64), fails, [&] { return calls >= 3; });
  EXPECT_TRUE(contains(got, 3) && contains(got, 60));
  EXPECT_LE(calls, 3);
  EXPECT_EQ(ddmin(Items{9}, fails), Items{9});  // one element: nothing to try
}

// Two objects of two triangles each and a third object of one, two materials, two lights.
Scene threeObjects() {
  Scene s = debugtest::litWindow();
  s.width = 32;
  s.height = 16;
  Material other = s.materials[0];
  other.name = "other";
  s.materials.push_back(other);
  debugtest::addQuad(s, -1.0f, 0.0f, -1.0f, 0.0f, 0.0f, "a");
  debugtest::addQuad(s, 0.0f, 1.0f, 0.0f, 1.0f, 0.0f, "b");
  s.objects.back().material = 1;
  Object c;
  c.name = "c";
  c.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  c.mesh.normals.assign(3, glm::vec3(0, 0, 1));
  c.mesh.triangles = {{0, 1, 2}};
  s.objects.push_back(c);
  s.lights = {debugtest::pointLight({0, 0, 3}), debugtest::directionalLight({0, 0, -1})};
  return s;
}

TEST(SceneSubset, KeepsTheChosenTrianglesAndWhatTheyUse) {
  const Scene base = threeObjects();
  const std::vector<PrimitiveRef> prims = flattenPrimitives(base);
  ASSERT_EQ(prims.size(), 5u);
  SceneSubset whole = SceneSubset::whole(base);
  EXPECT_EQ(whole.triangles, range(5));
  EXPECT_EQ(whole.lights, range(2));
  EXPECT_EQ(whole.width, 32);

  SceneSubset sub;
  sub.triangles = {3, 4};  // b's second triangle, c's only one
  sub.lights = {1};
  sub.width = 8;
  sub.height = 4;
  const Scene s = subsetScene(base, prims, sub);
  EXPECT_EQ(s.width, 8);
  EXPECT_EQ(s.height, 4);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::Directional);
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[0].name, "b");
  EXPECT_EQ(s.objects[1].name, "c");
  // b keeps triangle (0, 2, 3) as (0, 1, 2) over the three vertices it uses, in that order.
  ASSERT_EQ(s.objects[0].mesh.triangles.size(), 1u);
  EXPECT_EQ(s.objects[0].mesh.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  ASSERT_EQ(s.objects[0].mesh.positions.size(), 3u);
  EXPECT_EQ(s.objects[0].mesh.positions[1], base.objects[1].mesh.positions[2]);
  EXPECT_EQ(s.objects[0].mesh.positions[2], base.objects[1].mesh.positions[3]);
  EXPECT_EQ(s.objects[0].mesh.normals.size(), 3u);
  // Materials: only those used, renumbered in order of first use ("other" for b).
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[s.objects[0].material].name, "other");
  EXPECT_EQ(s.materials[s.objects[1].material].name, "m");
  // Keys tell subsets apart.
  EXPECT_NE(sub.key(), whole.key());
  SceneSubset same = sub;
  EXPECT_EQ(same.key(), sub.key());
}

TEST(ReduceScene, NeedsOneTriangleOneLightAndAMinimumSize) {
  const Scene base = threeObjects();
  std::vector<std::string> notes;
  std::set<std::string> seen;
  int tests = 0;
  ReduceHooks hooks;
  // Fails while object "b"'s second triangle, the directional light and a width of at
  // least 16 are there.
  hooks.fails = [&](const SceneSubset& c, const Scene& scene) {
    ++tests;
    EXPECT_TRUE(seen.insert(c.key()).second) << "tested twice: " << c.key();
    bool has_triangle = false;
    for (const Object& o : scene.objects)
      if (o.name == "b")
        for (const auto& t : o.mesh.triangles)
          if (o.mesh.positions[t[1]] == glm::vec3(1, 1, 0) &&
              o.mesh.positions[t[2]] == glm::vec3(0, 1, 0))
            has_triangle = true;
    const bool has_light =
        std::any_of(scene.lights.begin(), scene.lights.end(),
                    [](const Light& l) { return l.type == LightType::Directional; });
    return has_triangle && has_light && scene.width >= 16;
  };
  hooks.note = [&](const std::string& line) { notes.push_back(line); };
  const SceneSubset best = reduceScene(base, hooks);
  EXPECT_EQ(best.triangles, Items{3});
  EXPECT_EQ(best.lights, Items{1});
  EXPECT_EQ(best.width, 16);  // 32x16 -> 16x8; 8x4 passes
  EXPECT_EQ(best.height, 8);
  EXPECT_NE(std::find(notes.begin(), notes.end(), "image 16x8"), notes.end());
  EXPECT_GT(tests, 0);
  EXPECT_NE(std::find(notes.begin(), notes.end(), "1 triangles left"), notes.end());

  const Scene fixture =
      reducedFixture(base, best, "ref", "gl:egl:llvmpipe", FailClass::Shading, false);
  EXPECT_EQ(fixture.name, "debug/lit_window/reduced");
  EXPECT_NE(std::find(fixture.tags.begin(), fixture.tags.end(), "reduced"), fixture.tags.end());
  EXPECT_NE(fixture.description.find("5 -> 1 triangles, 3 -> 1 objects, 2 -> 1 lights"),
            std::string::npos)
      << fixture.description;
  EXPECT_NE(fixture.description.find("ref vs gl:egl:llvmpipe still fails in shading"),
            std::string::npos);
}

TEST(ReduceScene, OutOfTimeKeepsTheOriginal) {
  const Scene base = threeObjects();
  ReduceHooks hooks;
  hooks.fails = [](const SceneSubset&, const Scene&) { return true; };
  hooks.out_of_time = [] { return true; };
  const SceneSubset best = reduceScene(base, hooks);
  EXPECT_EQ(best.key(), SceneSubset::whole(base).key());
}

TEST(FailClasses, NamesAndStatuses) {
  PairResult r;
  r.depth.status = Status::Fail;
  r.shading.status = Status::Warn;
  EXPECT_EQ(failingClasses(r), std::vector<FailClass>{FailClass::Depth});
  EXPECT_EQ(failClassFromString("shading"), FailClass::Shading);
  EXPECT_FALSE(failClassFromString("colour").has_value());
  EXPECT_STREQ(toString(FailClass::Visibility), "visibility");
}

}  // namespace
}  // namespace rc
