// `rastercheck diff-runs OLD NEW [--json] [--out DIR]`: what changed between two run
// folders (e.g. two Mesa versions), from their report.json files; compare/run_diff.h
// does the matching and writes the text, JSON and HTML.
#include <iostream>

#include <fmt/format.h>

#include "app/commands.h"
#include "compare/atomic_file.h"
#include "compare/report_read.h"
#include "compare/run_diff.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;

int diffRunsCommand(const DiffRunsArgs& args) {
  const Report before = readReportFile(args.old_run / "report.json");
  const Report after = readReportFile(args.new_run / "report.json");
  const RunDiff diff = diffRuns(before, after, args.old_run.string(), args.new_run.string());
  if (!args.out.empty()) {
    std::error_code ec;
    if (fs::exists(args.out, ec) && !fs::is_directory(args.out, ec))
      throw InputError(
          fmt::format("{}: --out names a file; it must be a folder", args.out.string()));
    const bool created = !fs::exists(args.out, ec);
    fs::create_directories(args.out, ec);
    if (ec) throw InputError(fmt::format("{}: cannot create: {}", args.out.string(), ec.message()));
    try {
      AtomicFileSet files;
      files.stageText(args.out / "diff.txt", runDiffText(diff));
      files.stageText(args.out / "diff.json", runDiffJson(diff).dump(2) + "\n");
      files.stageText(args.out / "diff.html", runDiffHtml(diff));
      files.commit();
    } catch (...) {
      if (created) fs::remove(args.out, ec);
      throw;
    }
  }
  std::cout << (args.json ? runDiffJson(diff).dump(2) + "\n" : runDiffText(diff));
  return exitCodeFor(diff);
}

}  // namespace rc
