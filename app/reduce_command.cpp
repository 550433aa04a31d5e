// `rastercheck reduce SCENE --expected SPEC --actual SPEC --out MIN.json`: delta debugging
// (debug/reduce.h: ddmin over the scene's triangles, then its objects, its lights and the
// image size) down to a small fixture that still fails in the same class, written as an
// ordinary fixture (inline meshes, fixtures/scene_writer.h) for a bug report.
//
// Here: the predicate and the progress lines. The predicate renders both SPECs (the reference in
// this process, GL in a child process reading a fixture file, as `run` does) and compares them with
// the tolerances `compare` would use. A render that fails is "does not fail in the class" for ddmin
// (a crash is a different bug). Time is bounded: when it runs out, the smallest failing scene found
// so far is written.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <map>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/commands.h"
#include "app/debug_support.h"
#include "compare/compare.h"
#include "compare/pair_tolerances.h"
#include "compare/report.h"
#include "debug/reduce.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/resource_estimate.h"
#include "fixtures/scene_writer.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

class Reducer {
 public:
  Reducer(const ReduceArgs& args, Scene base)
      : args_(args),
        base_(std::move(base)),
        expected_(parseBackendSpec(args.expected)),
        actual_(parseBackendSpec(args.actual)),
        scratch_("reduce"),
        start_(Clock::now()),
        tty_(::isatty(STDERR_FILENO) != 0) {
    parseToleranceArgs(args.tolerance, cli_);
  }

  // Compares one scene. Throws BackendError only for the original scene.
  struct Outcome {
    bool rendered = false;
    PairResult result;
    std::string error;
  };
  Outcome compare(const Scene& scene) {
    Outcome out;
    const fs::path dir = scratch_.path() / fmt::format("test{}", tests_);
    fs::path file;
    try {
      if (expected_.kind == BackendSpec::Kind::Gl || actual_.kind == BackendSpec::Kind::Gl) {
        fs::create_directories(dir);
        file = dir / "scene.json";
        writeSceneFile(scene, file);
      }
      const Frame expected = renderBackend(expected_, scene, file);
      const Frame actual = renderBackend(actual_, scene, file);
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

  // The predicate of the reduction: a render that fails does not fail in the class.
  bool fails(const SceneSubset& c, const Scene& scene) {
    ++tests_;
    const Outcome o = compare(scene);
    const bool f = o.rendered && classStatus(o.result, class_) == Status::Fail;
    status(fmt::format("test {}: {} triangles, {} lights, {}x{}: {}", tests_, c.triangles.size(),
                       c.lights.size(), c.width, c.height, f ? "fails" : "passes"));
    if (f) failing_results_[c.key()] = o.result;
    return f;
  }

  bool outOfTime() {
    if (!timed_out_ && seconds() > args_.timeout_seconds) timed_out_ = true;
    return timed_out_;
  }

  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  int run() {
    // The original comparison decides the class (unless --class names one).
    const SceneSubset original = SceneSubset::whole(base_);
    // (As every candidate: the scene rebuilt from the subset, here of everything.)
    const Outcome first = compare(subsetScene(base_, flattenPrimitives(base_), original));
    if (!first.rendered) throw BackendError(first.error);
    ++tests_;
    std::vector<std::string> failing;
    for (FailClass c : failingClasses(first.result)) failing.emplace_back(toString(c));
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
    class_ = failClassFromString(wanted).value_or(FailClass::Shading);
    failing_results_[original.key()] = first.result;
    const std::size_t triangles = original.triangles.size();
    note(fmt::format("{} vs {} fails in {}: {} triangles, {} objects, {} lights, {}x{}",
                     args_.expected, args_.actual, wanted, triangles, base_.objects.size(),
                     base_.lights.size(), base_.width, base_.height));

    ReduceHooks hooks;
    hooks.fails = [this](const SceneSubset& c, const Scene& scene) { return fails(c, scene); };
    hooks.out_of_time = [this] { return outOfTime(); };
    hooks.note = [this](const std::string& line) { note(line); };
    const SceneSubset cur = reduceScene(base_, hooks);
    finishStatus();

    const Scene reduced =
        reducedFixture(base_, cur, args_.expected, args_.actual, class_, timed_out_);
    writeSceneFile(reduced, args_.out);

    std::cout << fmt::format(
        "{}: {} -> {} triangles, {} -> {} objects, {} -> {} lights, {}x{} -> {}x{} in {} tests, "
        "{:.1f} s\n",
        base_.name, triangles, cur.triangles.size(), base_.objects.size(), reduced.objects.size(),
        base_.lights.size(), cur.lights.size(), base_.width, base_.height, cur.width, cur.height,
        tests_, seconds());
    PairResult best_result = failing_results_.at(cur.key());
    best_result.fixture = reduced.name;
    best_result.expected = args_.expected;
    best_result.actual = args_.actual;
    std::cout << "still fails: " << describe(best_result) << '\n';
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
  const BackendSpec expected_;
  const BackendSpec actual_;
  CommandLineTolerances cli_;
  ScratchDir scratch_;
  const Clock::time_point start_;
  const bool tty_;
  std::size_t width_ = 0;
  FailClass class_ = FailClass::Visibility;
  std::map<std::string, PairResult> failing_results_;
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
