// See conformance_support.h.
#include "tests/conformance/conformance_support.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/worker_pool.h"
#include "compare/pair_images.h"
#include "compare/pair_tolerances.h"
#include "compare/report.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/scene_writer.h"

namespace rc::conformance {
namespace fs = std::filesystem;

std::vector<std::string> backends() {
  std::vector<std::string> out = {"gl:egl:llvmpipe", "gl:egl:softpipe", "gl:egl:zink"};
#ifdef RC_HAVE_OSMESA
  out.emplace_back("gl:osmesa:llvmpipe");
#endif
  return out;
}

std::vector<std::string> knownBackends() {
  return {"gl:egl:llvmpipe", "gl:egl:softpipe", "gl:egl:zink", "gl:osmesa:llvmpipe"};
}

namespace {

// Owns the scratch folder; its destructor runs when the test process exits normally
// (ctest runs one process per test, so every process would otherwise leave one behind).
class ScratchDir {
 public:
  ScratchDir() : path_(fs::temp_directory_path() / fmt::format("rc_conformance_{}", ::getpid())) {
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

fs::path scratchRoot() {
  static const ScratchDir dir;
  return dir.path();
}

std::optional<Frame> renderInChild(const fs::path& fixture, const std::string& spec,
                                   std::string& error, int& exit_code, const std::string& fault) {
  // `rastercheck worker` processes, as `run` keeps them (app/worker_pool.h): the frame comes
  // back through a pipe, so neither side encodes or decodes an image (and neither loads
  // OpenImageIO for it: fixtures/image_io.h), and every render of a test process with one
  // backend, faulted or not, shares one worker (the fault travels with the request).
  (void)scratchRoot();  // made first, so that it outlives the pool (its logs are in it)
  static WorkerPool pool([] {
    WorkerPool::Options options;
    options.log_dir = scratchRoot() / "workers";
    options.program = RC_EXE;
    return options;
  }());
  RenderOutcome outcome =
      pool.renderAll({RenderRequest{fs::absolute(fixture), spec, fault}}).front();
  if (outcome.ok) {
    exit_code = 0;
    return std::move(outcome.frame);
  }
  // What `rastercheck render` would have exited with: 2 for a bad fixture, else 3.
  exit_code = outcome.input_error ? 2 : 3;
  error = outcome.error;
  return std::nullopt;
}

Frame renderReference(const fs::path& fixture) {
  static const BackendSpec ref = parseBackendSpec("ref");
  return renderWith(ref, loadScene(fixture));
}

bool glRequired() {
  const char* env = std::getenv("RASTERCHECK_REQUIRE_GL");
  return env != nullptr && std::string(env) == "1";
}

bool backendStarts(const std::string& spec, std::string& why) {
  static std::map<std::string, std::pair<bool, std::string>> cache;
  auto it = cache.find(spec);
  if (it == cache.end()) {
    Scene probe;
    probe.name = "conformance/probe";
    probe.width = probe.height = 4;
    Material m;
    m.name = "m";
    probe.materials.push_back(m);
    Object o;
    o.name = "tri";
    o.mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    o.mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    o.mesh.triangles = {{0, 1, 2}};
    probe.objects.push_back(o);
    const fs::path file = scratchRoot() / "probe.json";
    writeSceneFile(probe, file);
    std::string error;
    int code = 0;
    const bool ok = renderInChild(file, spec, error, code).has_value();
    it = cache.emplace(spec, std::make_pair(ok, error)).first;
  }
  why = it->second.second;
  return it->second.first;
}

BackendRender renderWithBackend(const fs::path& fixture, const std::string& spec,
                                const std::string& fault) {
  BackendRender r;
  r.frame = renderInChild(fixture, spec, r.error, r.exit_code, fault);
  if (!r.frame && r.exit_code == 3) {
    std::string why;
    if (!backendStarts(spec, why)) {
      r.unavailable = true;
      r.error = why;
    }
  }
  return r;
}

std::set<std::string> failingClasses(const PairResult& r) {
  std::set<std::string> out;
  if (r.visibility.status == Status::Fail) out.insert("visibility");
  if (r.depth.status == Status::Fail) out.insert("depth");
  if (r.shading.status == Status::Fail) out.insert("shading");
  return out;
}

fs::path catalogDir() { return fs::path(RC_SOURCE_DIR) / "fixtures" / "scenes"; }

std::vector<std::string> catalogNames() {
  std::vector<std::string> out;
  for (const fs::path& file : findFixtures({catalogDir()})) {
    std::ifstream in(file);
    const auto doc = nlohmann::json::parse(in, nullptr, false);
    if (doc.is_object() && doc.contains("name") && doc["name"].is_string())
      out.push_back(doc["name"].get<std::string>());
  }
  return out;
}

fs::path expectationsFile() { return fs::path(RC_SOURCE_DIR) / "fixtures" / "expectations.json"; }

SuiteExpectations checkExpectations(const Expectations& parsed,
                                    const std::set<std::string>& fixtures,
                                    const std::vector<std::string>& known) {
  SuiteExpectations out;
  out.parsed = parsed;
  for (std::size_t i = 0; i < parsed.entries.size(); ++i) {
    const Expectation& e = parsed.entries[i];
    const std::string at = fmt::format("expectations[{}] ({})", i, e.id);
    const bool pattern = e.fixture.find_first_of("*?") != std::string::npos;
    if (!pattern && !fixtures.count(e.fixture))
      out.errors.push_back(
          fmt::format("{}.fixture: no fixture named \"{}\" in the catalog", at, e.fixture));
    bool any = false;
    for (const std::string& b : known) any = any || backendMatches(e.backend, b);
    if (!any)
      out.errors.push_back(
          fmt::format("{}.backend: \"{}\" matches none of the suite's backends", at, e.backend));
  }
  return out;
}

const SuiteExpectations& expectations() {
  static const SuiteExpectations checked = [] {
    try {
      const std::vector<std::string> names = catalogNames();
      return checkExpectations(readExpectations(expectationsFile()), {names.begin(), names.end()},
                               knownBackends());
    } catch (const InputError& e) {
      SuiteExpectations bad;
      bad.errors.emplace_back(e.what());
      return bad;
    }
  }();
  return checked;
}

Tolerances tolerancesFor(const Scene& scene, const Frame& expected, const Frame& actual) {
  return pairTolerances(expected, actual, scene.tolerance);
}

fs::path writeArtifacts(const std::string& test_name, const Frame& expected, const Frame& actual,
                        const Frame& uncertainty, PairResult& result) {
  fs::path dir = fs::path(RC_BINARY_DIR) / "conformance-artifacts" / fixtureSlug(test_name);
  ClassMaps maps;
  PairResult again = compareFrames(expected, actual, uncertainty, result.tolerances, &maps);
  again.fixture = result.fixture;
  again.expected = result.expected;
  again.actual = result.actual;
  writePairImages(expected, actual, maps, pairDirectory(dir, again), again);
  Report report;
  report.tool_version = "conformance";
  report.results.push_back(again);
  writeReport(report, dir);
  return dir;
}

}  // namespace rc::conformance
