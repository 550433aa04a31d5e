// Random fixtures of every generator profile written for a test, and a frame's pixel planes
// as bytes: shared by the tests that render many scenes and compare them bit for bit.
// Header-only, like the rest of tests/support.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fixtures/frame.h"
#include "fixtures/random_scene.h"

namespace rc::test {

// `count` random fixtures of `seed` under each of the profiles all, textures, blend, soups,
// lines and shadow, images up to max_width x max_height, written to dir/<profile>/ (dir emptied
// first): their files, sorted, without the generate.json records.
inline std::vector<std::filesystem::path> writeRandomProfiles(const std::filesystem::path& dir,
                                                              std::uint64_t seed, int count,
                                                              int max_width = 200,
                                                              int max_height = 150) {
  namespace fs = std::filesystem;
  fs::remove_all(dir);
  std::vector<fs::path> files;
  for (const RandomProfile profile :
       {RandomProfile::All, RandomProfile::Textures, RandomProfile::Blend, RandomProfile::Soups,
        RandomProfile::Lines, RandomProfile::Shadow}) {
    RandomSceneOptions o;
    o.seed = seed;
    o.count = static_cast<std::uint64_t>(count);
    o.max_width = max_width;
    o.max_height = max_height;
    o.profile = profile;
    const fs::path sub = dir / toString(profile);
    fs::create_directories(sub);
    writeRandomFixtures(o, sub);
    for (const auto& e : fs::directory_iterator(sub))
      if (e.path().extension() == ".json" && e.path().filename() != "generate.json")
        files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// writeRandomProfiles' fixtures (96x72 at most) and every fixture of the catalog folder
// `catalog`, sorted: the scenes the isolation tests draw in several orders and compare.
inline std::vector<std::filesystem::path> randomAndCatalog(const std::filesystem::path& dir,
                                                           std::uint64_t seed, int count,
                                                           const std::filesystem::path& catalog) {
  std::vector<std::filesystem::path> files = writeRandomProfiles(dir, seed, count, 96, 72);
  for (const auto& e : std::filesystem::recursive_directory_iterator(catalog))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Colour, depth and ids, and the per-sample ids and depths of a multisampled frame, as
// bytes: equal frames give equal strings.
inline std::string framePlanes(const Frame& f) {
  std::string out;
  auto add = [&out](const auto& v) {
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0]));
  };
  add(f.color);
  add(f.depth);
  add(f.id);
  add(f.sample_id);
  add(f.sample_depth);
  return out;
}

}  // namespace rc::test
