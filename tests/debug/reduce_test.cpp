// `rastercheck reduce` with reference-side predicates: painter's-algorithm failures
// (cyclic overlap, interpenetration, and a ~1000-triangle scene built here) must end with
// at most 3 triangles that still fail when run as an ordinary fixture; a scene that does
// not fail, a class that does not fail and a bad SPEC exit 2; a timeout still writes the
// smallest failing scene found.
#include "fixtures/loader.h"
#include "tests/debug/debug_test_util.h"

namespace rc::debugtest {
namespace {

std::size_t triangleCount(const Scene& s) {
  std::size_t n = 0;
  for (const Object& o : s.objects) n += o.mesh.triangles.size();
  return n;
}

// Reduces and checks the result is a loadable fixture, at most `max_triangles`, that
// `run` still fails in the same class.
Scene reduceAndCheck(const std::string& fixture, const std::string& expected,
                     const std::string& actual, std::size_t max_triangles, const fs::path& dir,
                     const std::string& env = "", const std::string& extra = "") {
  const fs::path out = dir / "min.json";
  const Result r = run("reduce " + fixture + " --expected " + expected + " --actual " + actual +
                           " --out " + out.string() + " " + extra,
                       env);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("reduce ["), std::string::npos) << "no progress shown: " << r.err;
  EXPECT_NE(r.out.find("still fails: FAIL"), std::string::npos) << r.out;
  Scene min = loadScene(out);
  EXPECT_LE(triangleCount(min), max_triangles);
  EXPECT_GE(triangleCount(min), 1u);
  EXPECT_NE(min.description.find("Reduced by rastercheck reduce from " + fixture),
            std::string::npos)
      << min.description;
  EXPECT_NE(min.description.find("still fails in visibility"), std::string::npos)
      << min.description;
  EXPECT_NE(std::find(min.tags.begin(), min.tags.end(), "reduced"), min.tags.end());
  // An ordinary fixture: `run` reproduces the failure.
  const Result again = run("run " + out.string() + " --backends " + actual + " --against " +
                               expected + " --no-variants --out " + (dir / "run").string(),
                           env);
  EXPECT_EQ(again.code, 1) << again.out << again.err;
  const json report = json::parse(std::ifstream(dir / "run" / "report.json"));
  EXPECT_EQ(report["results"][0]["visibility"]["status"], "fail") << report.dump(1);
  return min;
}

TEST(Reduce, CyclicOverlapUnderPainter) {
  const fs::path dir = scratch("reduce_cyclic");
  reduceAndCheck(catalog("zbuffer/cyclic_overlap_zbuffer.json"), "ref", "ref:painter", 3, dir);
  fs::remove_all(dir);
}

TEST(Reduce, InterpenetrationUnderPainterDropsLightsAndShrinksTheImage) {
  const fs::path dir = scratch("reduce_inter");
  const Scene min =
      reduceAndCheck(catalog("zbuffer/interpenetrating_ab.json"), "ref", "ref:painter", 3, dir);
  EXPECT_TRUE(min.lights.empty());  // visibility does not need the light
  EXPECT_LT(min.width, 128);
  fs::remove_all(dir);
}

TEST(Reduce, ThousandTrianglesDownToAFew) {
  // A sphere through a tilted floor, and a cube: the painter's sort fails where the sphere
  // crosses the floor.
  const fs::path dir = scratch("reduce_big");
  const fs::path scene = dir / "sphere_through_floor.json";
  std::ofstream(scene) << R"({"format": "rastercheck-scene/1", "name": "test/sphere_through_floor",
    "image": {"width": 128, "height": 128},
    "camera": {"eye": [0, 2, 5], "target": [0, 0, 0], "fovy_deg": 45, "near": 0.5, "far": 20},
    "ambient_light": [0.2, 0.2, 0.2],
    "lights": [{"type": "point", "position": [3, 4, 5]}, {"type": "directional", "direction": [0, -1, -1]}],
    "materials": {"a": {"diffuse": [0.8, 0.2, 0.2]}, "b": {"diffuse": [0.2, 0.8, 0.2]}},
    "objects": [{"name": "ball", "material": "a", "mesh": {"generator": "sphere", "segments": 32, "rings": 16}},
                {"name": "floor", "material": "b", "mesh": {"generator": "plane", "size": [4, 4]},
                 "transform": {"rotate_deg": {"axis": [1, 0, 0], "angle": -80}}},
                {"name": "box", "material": "b", "mesh": {"generator": "cube"},
                 "transform": {"translate": [1.5, 0, 0], "scale": [0.5, 0.5, 0.5]}}]})";
  ASSERT_GT(triangleCount(loadScene(scene)), 900u);
  const Scene min = reduceAndCheck(scene.string(), "ref", "ref:painter", 3, dir);
  EXPECT_LE(min.objects.size(), 2u);
  EXPECT_LE(min.materials.size(), 2u);  // unused materials are dropped
  fs::remove_all(dir);
}

TEST(Reduce, NothingToReduceExitsTwo) {
  const fs::path dir = scratch("reduce_none");
  const fs::path out = dir / "min.json";
  const Result same = run("reduce " + catalog("zbuffer/interpenetrating_ab.json") +
                          " --expected ref --actual ref --out " + out.string());
  EXPECT_EQ(same.code, 2) << same.err;
  EXPECT_EQ(lineCount(same.err), 1) << same.err;
  EXPECT_NE(same.err.find("nothing to reduce"), std::string::npos) << same.err;
  EXPECT_FALSE(fs::exists(out));
  const Result wrong_class =
      run("reduce " + catalog("zbuffer/interpenetrating_ab.json") +
          " --expected ref --actual ref:painter --class shading --out " + out.string());
  EXPECT_EQ(wrong_class.code, 2) << wrong_class.err;
  EXPECT_NE(wrong_class.err.find("does not fail in shading (it fails in visibility)"),
            std::string::npos)
      << wrong_class.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run("reduce x.json --expected ref --actual vulkan --out " + out.string()).code, 2);
  EXPECT_EQ(run("reduce " + catalog("zbuffer/interpenetrating_ab.json") +
                " --expected ref --actual ref:painter --class colour --out " + out.string())
                .code,
            2);
  fs::remove_all(dir);
}

TEST(Reduce, TimeoutWritesTheSmallestFailingSceneSoFar) {
  const fs::path dir = scratch("reduce_timeout");
  const fs::path out = dir / "min.json";
  const std::string fixture = catalog("zbuffer/cyclic_overlap_zbuffer.json");
  const Result r =
      run("reduce " + fixture + " --expected ref --actual ref:painter --timeout 1e-6 " + "--out " +
          out.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("timed out"), std::string::npos) << r.out;
  const Scene min = loadScene(out);
  EXPECT_EQ(triangleCount(min), triangleCount(loadScene(fixture)));  // nothing tested in time
  EXPECT_NE(min.description.find("time ran out"), std::string::npos) << min.description;
  const Result again =
      run("run " + out.string() + " --backends ref:painter --against ref --no-variants --out " +
          (dir / "run").string());
  EXPECT_EQ(again.code, 1) << again.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rc::debugtest
