// Delta debugging of a failing scene, the library side of `rastercheck reduce`: Zeller's
// ddmin over a list, the scene a choice of triangles, lights and image size stands for,
// and the reduction itself (triangles, then whole objects, then lights, then the image
// size). The predicate comes from the caller (app/ renders both backends, GL in a child
// process, and compares): nothing here renders.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "compare/compare.h"
#include "fixtures/scene.h"
#include "fixtures/scene_logic.h"

namespace rc {

// ddmin (Zeller and Hildebrandt, "Simplifying and isolating failure-inducing input", 2002)
// over `items`, which fail: a failing subset that is 1-minimal (removing any one element
// makes it pass) unless `stop` returned true first; then the smallest failing subset found.
// `fails` is called with subsets in the order of `items`; `reduced(n)` after each step that
// left n elements.
std::vector<std::uint32_t> ddmin(
    std::vector<std::uint32_t> items,
    const std::function<bool(const std::vector<std::uint32_t>&)>& fails,
    const std::function<bool()>& stop = {}, const std::function<void(std::size_t)>& reduced = {});

// A reduced scene, as choices over the original: which triangles (flattened indices, in
// order: flattenPrimitives), which lights (indices, in order), what image size.
struct SceneSubset {
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint32_t> lights;
  int width = 0;
  int height = 0;

  // Everything of `scene`.
  static SceneSubset whole(const Scene& scene);
  // Equal for equal subsets (memoisation).
  std::string key() const;
};

// The scene a subset stands for: objects keep their transforms and materials; each mesh
// keeps only the chosen triangles and the vertices they use (renumbered in order of first
// use); objects without triangles and unused materials are dropped. `primitives` is
// flattenPrimitives(base).
Scene subsetScene(const Scene& base, const std::vector<PrimitiveRef>& primitives,
                  const SceneSubset& subset);

// The classes a reduction can keep failing.
enum class FailClass { Visibility, Depth, Shading };
const char* toString(FailClass c);
std::optional<FailClass> failClassFromString(const std::string& name);
Status classStatus(const PairResult& result, FailClass c);
// The classes that fail in `result`, in the order visibility, depth, shading.
std::vector<FailClass> failingClasses(const PairResult& result);

// What the reduction calls back.
struct ReduceHooks {
  // Whether the scene of `subset` still fails in the class (rendered and compared; called
  // once per distinct subset).
  std::function<bool(const SceneSubset& subset, const Scene& scene)> fails;
  std::function<bool()> out_of_time;             // checked between tests; may stay true
  std::function<void(const std::string&)> note;  // progress that stays: a size went down
};

// Reduces `base` (which fails: the caller checked) dimension by dimension: triangles,
// whole objects among those left, lights (none at all first), then the image size halved
// while the aspect ratio stays exact. Returns the last failing subset found: minimal per
// dimension unless time ran out.
SceneSubset reduceScene(const Scene& base, const ReduceHooks& hooks);

// The reduced fixture for a bug report: subsetScene() named "<name>/reduced", tagged
// "reduced", its description saying where it came from and what still fails.
Scene reducedFixture(const Scene& base, const SceneSubset& best, const std::string& expected,
                     const std::string& actual, FailClass failing, bool timed_out);

}  // namespace rc
