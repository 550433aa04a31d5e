// `rastercheck reduce SCENE --expected SPEC --actual SPEC --out MIN.json`: delta debugging
// (Zeller's ddmin) over the scene's triangles, then its objects, its lights and the image
// size, down to a small fixture that still fails in the same class, written as an
// ordinary fixture (inline meshes, fixtures/scene_writer.h) for a bug report.
//
// The predicate renders both SPECs (the reference in this process, GL in a child process
// reading a fixture file, as `run` does) and compares them with the tolerances `compare`
// would use. A render that fails is "does not fail in the class" for ddmin (a crash is a
// different bug). Time is bounded: when it runs out, the smallest failing scene found so
// far is written.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <iostream>
#include <map>
#include <set>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/commands.h"
#include "app/debug_support.h"
#include "app/report_support.h"
#include "compare/compare.h"
#include "compare/report.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/scene_logic.h"
#include "fixtures/scene_writer.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

enum class FailClass { Visibility, Depth, Shading };
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

// A reduced scene, as choices over the original: which triangles (by flattened index,
// in order), which lights, what image size.
struct Candidate {
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint32_t> lights;
  int width = 0;
  int height = 0;

  std::string key() const {
    std::string k = fmt::format("{}x{}|", width, height);
    for (std::uint32_t t : triangles) k += fmt::format("{},", t);
    k += '|';
    for (std::uint32_t l : lights) k += fmt::format("{},", l);
    return k;
  }
};

// The scene a candidate stands for: objects keep their transforms and materials; each
// mesh keeps only the chosen triangles and the vertices they use (renumbered in order of
// first use); objects without triangles and unused materials are dropped.
Scene buildScene(const Scene& base, const std::vector<PrimitiveRef>& prims, const Candidate& c) {
  Scene s;
  s.source = base.source;
  s.name = base.name;
  s.description = base.description;
  s.tags = base.tags;
  s.width = c.width;
  s.height = c.height;
  s.clear_color = base.clear_color;
  s.clear_depth = base.clear_depth;
  s.camera = base.camera;
  s.ambient_light = base.ambient_light;
  s.state = base.state;
  s.tolerance = base.tolerance;
  for (std::uint32_t l : c.lights) s.lights.push_back(base.lights[l]);
  std::map<std::size_t, std::size_t> material_of;
  std::map<std::uint32_t, std::map<std::uint32_t, std::uint32_t>> remap;  // object -> vertex map
  std::map<std::uint32_t, std::size_t> object_of;
  for (std::uint32_t t : c.triangles) {
    const PrimitiveRef& p = prims[t];
    const Object& src = base.objects[p.object];
    auto it = object_of.find(p.object);
    if (it == object_of.end()) {
      Object o;
      o.name = src.name;
      o.model = src.model;
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
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = src.mesh.triangles[p.triangle][k];
      auto [slot, inserted] =
          vmap.emplace(v, static_cast<std::uint32_t>(dst.mesh.positions.size()));
      if (inserted) {
        dst.mesh.positions.push_back(src.mesh.positions[v]);
        dst.mesh.normals.push_back(src.mesh.normals[v]);
        if (!src.mesh.uvs.empty()) dst.mesh.uvs.push_back(src.mesh.uvs[v]);
      }
      tri[k] = slot->second;
    }
    dst.mesh.triangles.push_back(tri);
  }
  return s;
}

class Reducer {
 public:
  Reducer(const ReduceArgs& args, Scene base)
      : args_(args),
        base_(std::move(base)),
        prims_(flattenPrimitives(base_)),
        expected_(parseBackendSpec(args.expected)),
        actual_(parseBackendSpec(args.actual)),
        scratch_("reduce"),
        start_(Clock::now()),
        tty_(::isatty(STDERR_FILENO) != 0) {
    parseToleranceArgs(args.tolerance, cli_);
  }

  // Compares one candidate. Throws BackendError only for the original scene.
  struct Outcome {
    bool rendered = false;
    PairResult result;
    std::string error;
  };
  Outcome compare(const Candidate& c) {
    Outcome out;
    const Scene scene = buildScene(base_, prims_, c);
    const fs::path dir = scratch_.path() / fmt::format("test{}", tests_);
    fs::path file;
    try {
      if (expected_.kind == BackendSpec::Kind::Gl || actual_.kind == BackendSpec::Kind::Gl) {
        fs::create_directories(dir);
        file = dir / "scene.json";
        writeSceneFile(scene, file);
      }
      const Frame expected = renderBackend(expected_, scene, file, dir / "expected");
      const Frame actual = renderBackend(actual_, scene, file, dir / "actual");
      checkSameSize(expected, actual, args_.expected, args_.actual);
      Frame third;
      const Frame* uncertainty = &expected;
      if (!expected.hasUncertainty()) {
        if (actual.hasUncertainty()) {
          uncertainty = &actual;
        } else {
          third = renderReference(scene);
          uncertainty = &third;
        }
      }
      out.result = compareFrames(expected, actual, *uncertainty,
                                 pairTolerances(expected, actual, scene.tolerance, cli_));
      out.rendered = true;
    } catch (const BackendError& e) {
      out.error = e.what();
    } catch (const InputError& e) {
      out.error = e.what();
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    return out;
  }

  bool fails(const Candidate& c) {
    const std::string key = c.key();
    if (const auto it = memo_.find(key); it != memo_.end()) {
      if (it->second) {
        best_ = c;
        best_result_ = failing_results_.at(key);
      }
      return it->second;
    }
    ++tests_;
    const Outcome o = compare(c);
    const bool f = o.rendered && classStatus(o.result, class_) == Status::Fail;
    memo_[key] = f;
    status(fmt::format("test {}: {} triangles, {} lights, {}x{}: {}", tests_, c.triangles.size(),
                       c.lights.size(), c.width, c.height, f ? "fails" : "passes"));
    if (f) {
      best_ = c;
      best_result_ = o.result;
      failing_results_[key] = o.result;
    }
    return f;
  }

  bool outOfTime() {
    if (!timed_out_ && seconds() > args_.timeout_seconds) timed_out_ = true;
    return timed_out_;
  }

  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  // ddmin over the elements of one dimension of the candidate; `with` builds the
  // candidate for a subset. Returns the smallest failing subset found.
  template <class With>
  std::vector<std::uint32_t> ddmin(std::vector<std::uint32_t> items, const char* what, With with) {
    std::size_t n = 2;
    while (items.size() >= 2 && !outOfTime()) {
      n = std::min(n, items.size());
      std::vector<std::vector<std::uint32_t>> chunks(n);
      for (std::size_t k = 0; k < items.size(); ++k)
        chunks[k * n / items.size()].push_back(items[k]);
      bool reduced = false;
      for (const auto& chunk : chunks) {
        if (outOfTime()) break;
        if (fails(with(chunk))) {
          items = chunk;
          n = 2;
          reduced = true;
          break;
        }
      }
      if (!reduced && n > 2) {
        for (std::size_t k = 0; k < n && !reduced && !outOfTime(); ++k) {
          std::vector<std::uint32_t> complement;
          for (std::size_t o = 0; o < n; ++o)
            if (o != k) complement.insert(complement.end(), chunks[o].begin(), chunks[o].end());
          if (fails(with(complement))) {
            items = complement;
            n = std::max<std::size_t>(n - 1, 2);
            reduced = true;
          }
        }
      }
      if (reduced) {
        note(fmt::format("{} {} left", items.size(), what));
        continue;
      }
      if (n >= items.size()) break;
      n = std::min(n * 2, items.size());
    }
    return items;
  }

  int run() {
    // The original comparison decides the class (unless --class names one).
    Candidate original;
    for (std::uint32_t t = 0; t < prims_.size(); ++t) original.triangles.push_back(t);
    for (std::uint32_t l = 0; l < base_.lights.size(); ++l) original.lights.push_back(l);
    original.width = base_.width;
    original.height = base_.height;
    const Outcome first = compare(original);
    if (!first.rendered) throw BackendError(first.error);
    ++tests_;
    std::vector<std::string> failing;
    for (FailClass c : {FailClass::Visibility, FailClass::Depth, FailClass::Shading})
      if (classStatus(first.result, c) == Status::Fail) failing.emplace_back(toString(c));
    const std::string label = args_.scene.string();
    if (failing.empty())
      throw InputError(fmt::format("{}: {} vs {} does not fail ({}): nothing to reduce", label,
                                   args_.expected, args_.actual, describe(first.result)));
    const std::string wanted = args_.failure_class.empty() ? failing.front() : args_.failure_class;
    if (std::find(failing.begin(), failing.end(), wanted) == failing.end())
      throw InputError(
          fmt::format("{}: {} vs {} does not fail in {} (it fails in {}): nothing to "
                      "reduce",
                      label, args_.expected, args_.actual, wanted, fmt::join(failing, ", ")));
    class_ = wanted == "visibility" ? FailClass::Visibility
             : wanted == "depth"    ? FailClass::Depth
                                    : FailClass::Shading;
    memo_[original.key()] = true;
    failing_results_[original.key()] = first.result;
    best_ = original;
    best_result_ = first.result;
    note(fmt::format("{} vs {} fails in {}: {} triangles, {} objects, {} lights, {}x{}",
                     args_.expected, args_.actual, wanted, prims_.size(), base_.objects.size(),
                     base_.lights.size(), base_.width, base_.height));

    // 1. triangles
    Candidate cur = original;
    cur.triangles = ddmin(cur.triangles, "triangles", [&](const std::vector<std::uint32_t>& t) {
      Candidate c = cur;
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
          Candidate c = cur;
          c.triangles.clear();
          for (std::uint32_t t : cur.triangles)
            if (std::find(objs.begin(), objs.end(), prims_[t].object) != objs.end())
              c.triangles.push_back(t);
          return c;
        });
    if (kept_objects.size() < objects.size()) cur = best_;
    // 3. lights: none at all first (visibility and depth failures rarely need them)
    if (!cur.lights.empty() && !outOfTime()) {
      Candidate none = cur;
      none.lights.clear();
      if (fails(none)) {
        cur = none;
        note("no lights needed");
      } else {
        cur.lights = ddmin(cur.lights, "lights", [&](const std::vector<std::uint32_t>& l) {
          Candidate c = cur;
          c.lights = l;
          return c;
        });
      }
    }
    // 4. image size: halve while the aspect ratio stays exact and it still fails
    while (cur.width % 2 == 0 && cur.height % 2 == 0 && cur.width > 4 && cur.height > 4 &&
           !outOfTime()) {
      Candidate half = cur;
      half.width /= 2;
      half.height /= 2;
      if (!fails(half)) break;
      cur = half;
      note(fmt::format("image {}x{}", cur.width, cur.height));
    }
    // Everything above only ever moves to failing candidates; best_ is the last of them.
    cur = best_;
    finishStatus();

    Scene reduced = buildScene(base_, prims_, cur);
    const std::string from = base_.source.empty() ? base_.name : base_.source.string();
    reduced.name = base_.name + "/reduced";
    reduced.description = fmt::format(
        "Reduced by rastercheck reduce from {} ({}: {} -> {} triangles, {} -> {} objects, {} -> {} "
        "lights, {}x{} -> {}x{}): {} vs {} still fails in {}{}",
        from, base_.name, prims_.size(), cur.triangles.size(), base_.objects.size(),
        reduced.objects.size(), base_.lights.size(), cur.lights.size(), base_.width, base_.height,
        cur.width, cur.height, args_.expected, args_.actual, toString(class_),
        timed_out_ ? " (time ran out: not minimal)" : "");
    if (std::find(reduced.tags.begin(), reduced.tags.end(), "reduced") == reduced.tags.end())
      reduced.tags.emplace_back("reduced");
    writeSceneFile(reduced, args_.out);

    std::cout << fmt::format(
        "{}: {} -> {} triangles, {} -> {} objects, {} -> {} lights, {}x{} -> {}x{} in {} tests, "
        "{:.1f} s\n",
        base_.name, prims_.size(), cur.triangles.size(), base_.objects.size(),
        reduced.objects.size(), base_.lights.size(), cur.lights.size(), base_.width, base_.height,
        cur.width, cur.height, tests_, seconds());
    best_result_.fixture = reduced.name;
    best_result_.expected = args_.expected;
    best_result_.actual = args_.actual;
    std::cout << "still fails: " << describe(best_result_) << '\n';
    if (timed_out_)
      std::cout << fmt::format(
          "timed out after {:.0f} s: wrote the smallest failing scene found "
          "so far (not minimal)\n",
          args_.timeout_seconds);
    std::cout << "wrote " << args_.out.string() << '\n';
    std::cout << fmt::format("reproduce: rastercheck run {} --backends {} --against {} --out DIR\n",
                             args_.out.string(), args_.actual, args_.expected);
    return kExitPass;
  }

 private:
  void status(const std::string& line) {
    if (!tty_) return;
    std::string s = fmt::format("[{:6.1f}s] {}", seconds(), line);
    if (s.size() > 110) s.resize(110);
    std::cerr << '\r' << s << std::string(width_ > s.size() ? width_ - s.size() : 0, ' ')
              << std::flush;
    width_ = s.size();
  }
  void finishStatus() {
    if (tty_ && width_ > 0) std::cerr << '\r' << std::string(width_, ' ') << '\r' << std::flush;
    width_ = 0;
  }
  // A line that stays: the size went down (or the start).
  void note(const std::string& line) {
    finishStatus();
    std::cerr << fmt::format("reduce [{:6.1f}s, {} tests] {}\n", seconds(), tests_, line);
  }

  const ReduceArgs& args_;
  const Scene base_;
  const std::vector<PrimitiveRef> prims_;
  const BackendSpec expected_;
  const BackendSpec actual_;
  CommandLineTolerances cli_;
  ScratchDir scratch_;
  const Clock::time_point start_;
  const bool tty_;
  std::size_t width_ = 0;
  FailClass class_ = FailClass::Visibility;
  std::map<std::string, bool> memo_;
  std::map<std::string, PairResult> failing_results_;
  Candidate best_;
  PairResult best_result_;
  int tests_ = 0;
  bool timed_out_ = false;
};

}  // namespace

int reduceCommand(const ReduceArgs& args) {
  parseBackendSpec(args.expected);  // usage errors before any work
  parseBackendSpec(args.actual);
  if (!(args.timeout_seconds > 0.0))
    throw InputError(
        fmt::format("--timeout {}: must be a positive number of seconds", args.timeout_seconds));
  if (args.out.extension() != ".json")
    throw InputError(
        fmt::format("--out {}: the minimal fixture is a .json file", args.out.string()));
  Scene scene = loadScene(args.scene);
  checkResources(scene, rendererKind(parseBackendSpec(args.expected)), ResourceLimits::current());
  checkResources(scene, rendererKind(parseBackendSpec(args.actual)), ResourceLimits::current());
  Reducer reducer(args, std::move(scene));
  return reducer.run();
}

}  // namespace rc
