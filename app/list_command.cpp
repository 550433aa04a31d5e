// `rastercheck list [PATH...]`: the fixture catalog (name, tags, description) as text,
// JSON or the Markdown table fixtures/README.md is generated from.
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/paths.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"

namespace rc {

int listCommand(const ListArgs& args) {
  std::vector<std::filesystem::path> roots = args.paths;
  if (roots.empty()) roots.push_back(defaultCatalogDir());
  struct Row {
    std::string name, tags, description, file;
  };
  std::vector<Row> rows;
  for (const auto& file : findFixtures(roots)) {
    const Scene scene = loadScene(file);
    std::string tags;
    for (const auto& t : scene.tags) tags += (tags.empty() ? "" : ", ") + t;
    rows.push_back({scene.name, tags, scene.description, file.string()});
  }
  if (args.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const Row& r : rows)
      out.push_back(
          {{"name", r.name}, {"tags", r.tags}, {"description", r.description}, {"file", r.file}});
    std::cout << out.dump(2) << '\n';
  } else if (args.markdown) {
    std::cout << "| fixture | tags | description |\n|---|---|---|\n";
    for (const Row& r : rows)
      std::cout << fmt::format("| `{}` | {} | {} |\n", r.name, r.tags, r.description);
  } else {
    std::size_t width = 7;
    for (const Row& r : rows) width = std::max(width, r.name.size());
    for (const Row& r : rows)
      std::cout << fmt::format("{:<{}}  [{}]  {}\n", r.name, width, r.tags, r.description);
    std::cout << fmt::format("{} fixtures\n", rows.size());
  }
  return kExitPass;
}

}  // namespace rc
