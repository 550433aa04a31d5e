// `rastercheck accuracy RUN_DIR... [--out FILE]`: the accuracy report (docs/accuracy.md)
// from the report.json of `run` folders; the tables are built by compare/accuracy.h.
#include <iostream>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/paths.h"
#include "compare/accuracy.h"
#include "fixtures/errors.h"
#include "fixtures/output_folder.h"

namespace rc {

int accuracyCommand(const AccuracyArgs& args) {
  std::vector<std::filesystem::path> catalogs = args.catalogs;
  if (catalogs.empty()) catalogs.push_back(defaultCatalogDir());
  AccuracyData data = readAccuracyRuns(args.runs, catalogs);
  if (!args.expectations.empty()) data.known = readExpectations(args.expectations);
  const std::string command = args.command.empty() ? "`rastercheck accuracy`" : args.command;
  const std::string md = accuracyMarkdown(data, command);
  if (args.out.empty()) {
    std::cout << md;
  } else {
    OutputFile file(args.out);
    file.writeText(md);
    file.commit();
    std::cout << fmt::format("{} comparisons -> {}\n", data.pairs.size(), args.out.string());
  }
  return kExitPass;
}

}  // namespace rc
