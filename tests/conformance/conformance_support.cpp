// See conformance_support.h.
#include "tests/conformance/conformance_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "compare/pair_images.h"
#include "compare/report.h"
#include "fixtures/catalog.h"
#include "fixtures/frame_io.h"
#include "fixtures/scene_writer.h"

namespace rc::conformance {
namespace fs = std::filesystem;

std::vector<std::string> backends() {
  std::vector<std::string> out = {"gl:egl:llvmpipe", "gl:egl:softpipe"};
#ifdef RC_HAVE_OSMESA
  out.push_back("gl:osmesa:llvmpipe");
#endif
  return out;
}

namespace {

fs::path scratchRoot() {
  fs::path p = fs::temp_directory_path() / fmt::format("rc_conformance_{}", ::getpid());
  fs::create_directories(p);
  return p;
}

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

std::optional<Frame> renderInChild(const fs::path& fixture, const std::string& spec,
                                   std::string& error, int& exit_code) {
  static int counter = 0;
  const fs::path out = scratchRoot() / fmt::format("frame{}", counter++);
  const std::string cmd =
      fmt::format("{} render {} --backend {} --out {} 2>&1", RC_EXE, shellQuote(fixture.string()),
                  shellQuote(spec), shellQuote(out.string()));
  std::string output;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) {
    error = "popen failed";
    exit_code = -1;
    return std::nullopt;
  }
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  const int status = ::pclose(p);
  exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (exit_code != 0) {
    while (!output.empty() && output.back() == '\n') output.pop_back();
    error = output.substr(output.rfind('\n') == std::string::npos ? 0 : output.rfind('\n') + 1);
    return std::nullopt;
  }
  Frame frame = readFrameDir(out);
  fs::remove_all(out);
  return frame;
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

std::set<std::string> failingClasses(const PairResult& r) {
  std::set<std::string> out;
  if (r.visibility.status == Status::Fail) out.insert("visibility");
  if (r.depth.status == Status::Fail) out.insert("depth");
  if (r.shading.status == Status::Fail) out.insert("shading");
  return out;
}

const std::vector<Expectation>& expectations() {
  static const std::vector<Expectation> list = [] {
    std::vector<Expectation> out;
    const fs::path file = fs::path(RC_SOURCE_DIR) / "tests/conformance/expectations.json";
    std::ifstream in(file);
    const nlohmann::json doc = nlohmann::json::parse(in);
    for (const auto& e : doc.at("expectations")) {
      out.push_back({e.at("fixture").get<std::string>(), e.at("backend").get<std::string>(),
                     e.at("class").get<std::string>(), e.at("reason").get<std::string>()});
    }
    return out;
  }();
  return list;
}

bool backendMatches(const std::string& pattern, const std::string& backend) {
  auto split = [](const std::string& s) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= s.size(); ++i) {
      if (i == s.size() || s[i] == ':') {
        parts.push_back(s.substr(start, i - start));
        start = i + 1;
      }
    }
    return parts;
  };
  const auto p = split(pattern);
  const auto b = split(backend);
  if (p.size() != b.size()) return false;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p[i] != "*" && p[i] != b[i]) return false;
  return true;
}

std::vector<Expectation> expectationsFor(const std::string& fixture, const std::string& backend) {
  std::vector<Expectation> out;
  for (const Expectation& e : expectations())
    if (e.fixture == fixture && backendMatches(e.backend, backend)) out.push_back(e);
  return out;
}

Tolerances tolerancesFor(const Scene& scene, const Frame& expected, const Frame& actual) {
  Tolerances tol = tolerancesForFrames(expected, actual);
  applyOverrides(tol, scene.tolerance);
  return tol;
}

fs::path writeArtifacts(const std::string& test_name, const Frame& expected, const Frame& actual,
                        const Frame& uncertainty, PairResult& result) {
  const fs::path dir = fs::path(RC_BINARY_DIR) / "conformance-artifacts" / fixtureSlug(test_name);
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
