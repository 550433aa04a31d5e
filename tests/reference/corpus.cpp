// The determinism corpus: see corpus.h.
#include "tests/reference/corpus.h"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "fixtures/loader.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc::test {

std::vector<std::filesystem::path> fixtureFiles(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".json")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

void renderCorpus(const std::vector<std::filesystem::path>& fixtures, bool with_bench,
                  const std::function<void(const std::string&, const Frame&)>& sink) {
  const std::pair<const char*, ReferenceOptions> options[] = {
      {"ref", ReferenceOptions{8, false, true}},
      {"ref:subpixel=4", ReferenceOptions{4, false, true}},
      {"ref:subpixel=12:painter", ReferenceOptions{12, true, true}},
      {"ref(no-uncertainty)", ReferenceOptions{8, false, false}},
  };
  auto renderAll = [&](const std::string& name, const Scene& scene) {
    for (const auto& [label, opt] : options) sink(name + " " + label, renderReference(scene, opt));
  };
  for (const NamedScene& s : featureScenes()) renderAll(s.name, s.scene);
  for (const auto& file : fixtures) renderAll(file.string(), loadScene(file));
  if (!with_bench) return;
  renderAll("bench/small_triangles", smallTrianglesScene());
  for (Shading sh : {Shading::Flat, Shading::Gouraud, Shading::Phong})
    renderAll(std::string("bench/layers_") + toString(sh), layersScene(sh));
}

std::uint64_t frameHash(const Frame& frame) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : frameBytes(frame)) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string corpusHashes(const std::vector<std::filesystem::path>& fixtures, bool with_bench) {
  std::string out;
  renderCorpus(fixtures, with_bench, [&](const std::string& name, const Frame& frame) {
    out += fmt::format("{:016x} {}\n", frameHash(frame), name);
  });
  return out;
}

}  // namespace rc::test
