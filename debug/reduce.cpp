// Delta debugging of a failing scene: see reduce.h.
#include "debug/reduce.h"

#include <algorithm>
#include <array>
#include <map>

#include <fmt/format.h>

namespace rc {

std::vector<std::uint32_t> ddmin(
    std::vector<std::uint32_t> items,
    const std::function<bool(const std::vector<std::uint32_t>&)>& fails,
    const std::function<bool()>& stop, const std::function<void(std::size_t)>& reduced_to) {
  auto stopped = [&] { return stop && stop(); };
  std::size_t n = 2;
  while (items.size() >= 2 && !stopped()) {
    n = std::min(n, items.size());
    std::vector<std::vector<std::uint32_t>> chunks(n);
    for (std::size_t k = 0; k < items.size(); ++k) chunks[k * n / items.size()].push_back(items[k]);
    bool reduced = false;
    // Reduce to a subset: one chunk alone still fails.
    for (const auto& chunk : chunks) {
      if (stopped()) break;
      if (fails(chunk)) {
        items = chunk;
        n = 2;
        reduced = true;
        break;
      }
    }
    // Reduce to a complement: everything but one chunk still fails.
    if (!reduced && n > 2) {
      for (std::size_t k = 0; k < n && !reduced && !stopped(); ++k) {
        std::vector<std::uint32_t> complement;
        for (std::size_t o = 0; o < n; ++o)
          if (o != k) complement.insert(complement.end(), chunks[o].begin(), chunks[o].end());
        if (fails(complement)) {
          items = complement;
          n = std::max<std::size_t>(n - 1, 2);
          reduced = true;
        }
      }
    }
    if (reduced) {
      if (reduced_to) reduced_to(items.size());
      continue;
    }
    if (n >= items.size()) break;       // single elements tried: 1-minimal
    n = std::min(n * 2, items.size());  // finer granularity
  }
  return items;
}

SceneSubset SceneSubset::whole(const Scene& scene) {
  SceneSubset s;
  const std::size_t triangles = flattenPrimitives(scene).size();
  for (std::uint32_t t = 0; t < triangles; ++t) s.triangles.push_back(t);
  for (std::uint32_t l = 0; l < scene.lights.size(); ++l) s.lights.push_back(l);
  s.width = scene.width;
  s.height = scene.height;
  return s;
}

std::string SceneSubset::key() const {
  std::string k = fmt::format("{}x{}|", width, height);
  for (std::uint32_t t : triangles) k += fmt::format("{},", t);
  k += '|';
  for (std::uint32_t l : lights) k += fmt::format("{},", l);
  return k;
}

Scene subsetScene(const Scene& base, const std::vector<PrimitiveRef>& primitives,
                  const SceneSubset& subset) {
  Scene s;
  s.source = base.source;
  s.name = base.name;
  s.description = base.description;
  s.tags = base.tags;
  s.width = subset.width;
  s.height = subset.height;
  s.clear_color = base.clear_color;
  s.clear_depth = base.clear_depth;
  s.camera = base.camera;
  s.ambient_light = base.ambient_light;
  s.state = base.state;
  s.tolerance = base.tolerance;
  for (std::uint32_t l : subset.lights) s.lights.push_back(base.lights[l]);
  std::map<std::size_t, std::size_t> material_of;
  std::map<std::uint32_t, std::map<std::uint32_t, std::uint32_t>> remap;  // object -> vertex map
  std::map<std::uint32_t, std::size_t> object_of;
  for (std::uint32_t t : subset.triangles) {
    const PrimitiveRef& p = primitives[t];
    const Object& src = base.objects[p.object];
    auto it = object_of.find(p.object);
    if (it == object_of.end()) {
      Object o;
      o.name = src.name;
      o.model = src.model;
      o.state = src.state;
      // A strip's or loop's kept segments are written as explicit lines.
      o.primitive = isLineKind(src.primitive) ? PrimitiveKind::Lines : src.primitive;
      auto m = material_of.find(src.material);
      if (m == material_of.end()) {
        m = material_of.emplace(src.material, s.materials.size()).first;
        s.materials.push_back(base.materials[src.material]);
      }
      o.material = m->second;
      it = object_of.emplace(p.object, s.objects.size()).first;
      s.objects.push_back(std::move(o));
    }
    Object& dst = s.objects[it->second];
    std::map<std::uint32_t, std::uint32_t>& vmap = remap[p.object];
    std::uint32_t source[3];
    const int n = primitiveVertices(src, p.triangle, source);
    std::array<std::uint32_t, 3> kept{};
    for (int k = 0; k < n; ++k) {
      const std::uint32_t v = source[k];
      auto [slot, inserted] =
          vmap.emplace(v, static_cast<std::uint32_t>(dst.mesh.positions.size()));
      if (inserted) {
        dst.mesh.positions.push_back(src.mesh.positions[v]);
        dst.mesh.normals.push_back(src.mesh.normals[v]);
        if (!src.mesh.uvs.empty()) dst.mesh.uvs.push_back(src.mesh.uvs[v]);
      }
      kept[static_cast<std::size_t>(k)] = slot->second;
    }
    if (n == 3) dst.mesh.triangles.push_back(kept);
    if (n == 2) dst.mesh.lines.push_back({kept[0], kept[1]});
    // A point is its position: one was appended above (each point its own vertex).
  }
  // Multi-pass: the same targets and passes, each pass drawing what is left of its
  // objects (a pass whose objects are all gone draws nothing).
  s.targets = base.targets;
  s.passes = base.passes;
  for (ScenePass& pass : s.passes) {
    if (!pass.objects) continue;
    std::vector<std::size_t> kept;
    for (std::size_t o : *pass.objects)
      if (auto it = object_of.find(static_cast<std::uint32_t>(o)); it != object_of.end())
        kept.push_back(it->second);
    std::sort(kept.begin(), kept.end());
    pass.objects = std::move(kept);
  }
  return s;
}

const char* toString(FailClass c) {
  switch (c) {
    case FailClass::Visibility:
      return "visibility";
    case FailClass::Depth:
      return "depth";
    case FailClass::Shading:
      return "shading";
  }
  return "?";
}

std::optional<FailClass> failClassFromString(const std::string& name) {
  for (FailClass c : {FailClass::Visibility, FailClass::Depth, FailClass::Shading})
    if (name == toString(c)) return c;
  return std::nullopt;
}

Status classStatus(const PairResult& r, FailClass c) {
  switch (c) {
    case FailClass::Visibility:
      return r.visibility.status;
    case FailClass::Depth:
      return r.depth.status;
    case FailClass::Shading:
      return r.shading.status;
  }
  return Status::Pass;
}

std::vector<FailClass> failingClasses(const PairResult& result) {
  std::vector<FailClass> out;
  for (FailClass c : {FailClass::Visibility, FailClass::Depth, FailClass::Shading})
    if (classStatus(result, c) == Status::Fail) out.push_back(c);
  return out;
}

namespace {

class Reduction {
 public:
  Reduction(const Scene& base, const ReduceHooks& hooks)
      : base_(base), prims_(flattenPrimitives(base)), hooks_(hooks) {}

  SceneSubset run() {
    const SceneSubset original = SceneSubset::whole(base_);
    memo_[original.key()] = true;  // the caller saw it fail
    best_ = original;

    // 1. triangles
    SceneSubset cur = original;
    cur.triangles = ddmin(cur.triangles, "triangles", [&](const std::vector<std::uint32_t>& t) {
      SceneSubset c = cur;
      c.triangles = t;
      return c;
    });
    // 2. objects: whole objects among what is left
    std::vector<std::uint32_t> objects;
    for (std::uint32_t t : cur.triangles)
      if (objects.empty() || objects.back() != prims_[t].object)
        objects.push_back(prims_[t].object);
    const std::vector<std::uint32_t> kept_objects =
        ddmin(objects, "objects", [&](const std::vector<std::uint32_t>& objs) {
          SceneSubset c = cur;
          c.triangles.clear();
          for (std::uint32_t t : cur.triangles)
            if (std::find(objs.begin(), objs.end(), prims_[t].object) != objs.end())
              c.triangles.push_back(t);
          return c;
        });
    if (kept_objects.size() < objects.size()) cur = best_;
    // 3. lights: none at all first (visibility and depth failures rarely need them)
    if (!cur.lights.empty() && !outOfTime()) {
      SceneSubset none = cur;
      none.lights.clear();
      if (fails(none)) {
        cur = none;
        note("no lights needed");
      } else {
        cur.lights = ddmin(cur.lights, "lights", [&](const std::vector<std::uint32_t>& l) {
          SceneSubset c = cur;
          c.lights = l;
          return c;
        });
      }
    }
    // 4. image size: halve while the aspect ratio stays exact and it still fails
    while (cur.width % 2 == 0 && cur.height % 2 == 0 && cur.width > 4 && cur.height > 4 &&
           !outOfTime()) {
      SceneSubset half = cur;
      half.width /= 2;
      half.height /= 2;
      if (!fails(half)) break;
      cur = half;
      note(fmt::format("image {}x{}", cur.width, cur.height));
    }
    // Everything above only ever moves to failing subsets; best_ is the last of them.
    return best_;
  }

 private:
  bool fails(const SceneSubset& c) {
    const std::string key = c.key();
    if (const auto it = memo_.find(key); it != memo_.end()) {
      if (it->second) best_ = c;
      return it->second;
    }
    const bool f = hooks_.fails(c, subsetScene(base_, prims_, c));
    memo_[key] = f;
    if (f) best_ = c;
    return f;
  }

  bool outOfTime() const { return hooks_.out_of_time && hooks_.out_of_time(); }
  void note(const std::string& line) const {
    if (hooks_.note) hooks_.note(line);
  }

  // ddmin over one dimension of the subset; `with` builds the subset for a choice.
  template <class With>
  std::vector<std::uint32_t> ddmin(std::vector<std::uint32_t> items, const char* what, With with) {
    return rc::ddmin(
        std::move(items), [&](const std::vector<std::uint32_t>& s) { return fails(with(s)); },
        [&] { return outOfTime(); },
        [&](std::size_t n) { note(fmt::format("{} {} left", n, what)); });
  }

  const Scene& base_;
  const std::vector<PrimitiveRef> prims_;
  const ReduceHooks& hooks_;
  std::map<std::string, bool> memo_;
  SceneSubset best_;
};

}  // namespace

SceneSubset reduceScene(const Scene& base, const ReduceHooks& hooks) {
  return Reduction(base, hooks).run();
}

Scene reducedFixture(const Scene& base, const SceneSubset& best, const std::string& expected,
                     const std::string& actual, FailClass failing, bool timed_out) {
  const std::vector<PrimitiveRef> prims = flattenPrimitives(base);
  Scene reduced = subsetScene(base, prims, best);
  const std::string from = base.source.empty() ? base.name : base.source.string();
  reduced.name = base.name + "/reduced";
  reduced.description = fmt::format(
      "Reduced by rastercheck reduce from {} ({}: {} -> {} triangles, {} -> {} objects, {} -> {} "
      "lights, {}x{} -> {}x{}): {} vs {} still fails in {}{}",
      from, base.name, prims.size(), best.triangles.size(), base.objects.size(),
      reduced.objects.size(), base.lights.size(), best.lights.size(), base.width, base.height,
      best.width, best.height, expected, actual, toString(failing),
      timed_out ? " (time ran out: not minimal)" : "");
  if (std::find(reduced.tags.begin(), reduced.tags.end(), "reduced") == reduced.tags.end())
    reduced.tags.emplace_back("reduced");
  return reduced;
}

}  // namespace rc
