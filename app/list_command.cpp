// `rastercheck list [PATH...]`: the fixture catalog (name, tags, description) as text,
// JSON or the Markdown table fixtures/README.md is generated from
// (scripts/gen-fixture-readme.sh).
#include <iostream>
#include <map>

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
    std::string name;
    std::vector<std::string> tags;
    std::string description, file;
  };
  std::vector<Row> rows;
  for (const auto& file : findFixtures(roots)) {
    const Scene scene = loadScene(file);
    rows.push_back({scene.name, scene.tags, scene.description, file.string()});
  }
  auto joined = [](const std::vector<std::string>& tags) {
    std::string out;
    for (const auto& t : tags) out += (out.empty() ? "" : ", ") + t;
    return out;
  };
  if (args.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const Row& r : rows)
      out.push_back(
          {{"name", r.name}, {"tags", r.tags}, {"description", r.description}, {"file", r.file}});
    std::cout << out.dump(2) << '\n';
  } else if (args.markdown) {
    // A '|' inside a cell would end it.
    auto cell = [](const std::string& s) {
      std::string out;
      for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
      return out;
    };
    std::cout << "| fixture | tags | description |\n|---|---|---|\n";
    std::map<std::string, int> per_tag;
    for (const Row& r : rows) {
      std::cout << fmt::format("| `{}` | {} | {} |\n", r.name, cell(joined(r.tags)),
                               cell(r.description));
      for (const auto& t : r.tags) ++per_tag[t];
    }
    std::cout << fmt::format("\n{} fixtures.\n\n| tag | fixtures |\n|---|---|\n", rows.size());
    for (const auto& [tag, count] : per_tag)
      std::cout << fmt::format("| {} | {} |\n", cell(tag), count);
  } else {
    std::size_t width = 7;
    for (const Row& r : rows) width = std::max(width, r.name.size());
    for (const Row& r : rows)
      std::cout << fmt::format("{:<{}}  [{}]  {}\n", r.name, width, joined(r.tags), r.description);
    std::cout << fmt::format("{} fixtures\n", rows.size());
  }
  return kExitPass;
}

}  // namespace rc
