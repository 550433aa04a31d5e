// `rastercheck merge RUN_DIR... --out DIR`: the folders of `run --shard K/N` joined into
// the report one unsharded run would have written (report.json rows in the whole run's
// order, junit.xml, report.html, pair images and kept frames), replacing DIR's outputs
// all-or-nothing; with --baseline/--flakes/--skips, deqp-runner's verdict on the whole run.
// The joining itself is compare/shards.h.
#include <iostream>
#include <set>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/report_support.h"
#include "compare/deqp_results.h"
#include "compare/pair_images.h"
#include "compare/shards.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

// A hard link where the file system allows one (shard folders are usually on the same
// disk as the merged one), else a copy.
void linkOrCopy(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::create_directories(to.parent_path(), ec);
  fs::create_hard_link(from, to, ec);
  if (!ec) return;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec)
    throw InputError(
        fmt::format("{}: cannot copy to {}: {}", from.string(), to.string(), ec.message()));
}

}  // namespace

int mergeCommand(const MergeArgs& args) {
  for (const fs::path& run : args.runs) {
    std::error_code ec;
    if (fs::equivalent(run, args.out, ec) ||
        fs::absolute(run).lexically_normal() == fs::absolute(args.out).lexically_normal())
      throw InputError(fmt::format("{}: --out must not be one of the run folders", run.string()));
  }
  const RunnerFiles runner = readRunnerFiles(args.baseline, args.flakes, args.skips);
  MergedRuns merged = mergeRunReports(args.runs);
  ReportFolder folder(args.out);
  // Pair images: into folders chosen as the whole run chooses them (unique whatever the
  // names: ReportFolder::pairDirectory).
  for (PairResult& r : merged.report.results) {
    if (r.images.empty()) continue;
    const fs::path dir = folder.pairDirectory(r);
    for (auto& [kind, file] : r.images) {
      const fs::path target = dir / file.filename();
      linkOrCopy(file, target);
      file = target;
    }
  }
  // Frames of retried renders: kept beside the others, at the same place under frames/.
  for (PairResult& r : merged.report.results)
    for (PairResult::Attempt& a : r.attempts) {
      if (a.frame.empty()) continue;
      for (const fs::path& run : args.runs) {
        const fs::path rel = fs::absolute(a.frame).lexically_normal().lexically_relative(
            fs::absolute(run).lexically_normal());
        if (rel.empty() || *rel.begin() == "..") continue;
        a.frame = (folder.staging() / rel).string();
        break;
      }
    }
  // Kept frames: the same fixture's reference frame can be in several shards (identical).
  for (const fs::path& run : args.runs) {
    const fs::path frames = run / "frames";
    std::error_code ec;
    if (!fs::is_directory(frames, ec)) continue;
    for (const auto& e : fs::recursive_directory_iterator(frames)) {
      if (!e.is_regular_file()) continue;
      const fs::path target = folder.staging() / "frames" / e.path().lexically_relative(frames);
      if (!fs::exists(target, ec)) linkOrCopy(e.path(), target);
    }
  }
  // The deqp-runner files, applied to the whole run (a part's own verdict is its own).
  if (runner.any()) {
    for (PairResult& r : merged.report.results) r.runner_status.clear();
    applyRunnerFiles(runner, merged.report);
  }
  folder.commit(merged.report);
  printSummary(merged.report, args.out, std::cout);
  return exitCodeFor(merged.report);
}

}  // namespace rc
