// `rastercheck campaign --seed S --count N --backends SPEC,... --out DIR`: random scenes
// rendered and compared in batches by child `rastercheck run` processes, every failing
// class of every pair reduced by a child `rastercheck reduce` (bounded by
// --reduce-seconds), the reduced fixture probed by one more `run` (debug/probes.h), and
// the failures grouped by signature into DIR/summary.md, summary.json and index.html
// (debug/campaign.h). Every step's result is a file renamed into place when complete, so
// Ctrl-C keeps what is done and the same command continues from there.
// docs/campaigns.md describes the folder and the summary.
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "app/backends.h"
#include "app/campaign_support.h"
#include "app/commands.h"
#include "app/paths.h"
#include "app/report_support.h"
#include "app/subprocess.h"
#include "compare/atomic_file.h"
#include "compare/tolerances.h"
#include "debug/campaign.h"
#include "debug/probes.h"
#include "fixtures/errors.h"
#include "fixtures/output_folder.h"
#include "fixtures/scene_writer.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// A run folder's name: the first and last scene index it covers.
struct SceneRange {
  std::uint64_t first = 0;
  std::uint64_t last = 0;
  std::string name() const { return fmt::format("{:05}-{:05}", first, last); }
};

std::optional<SceneRange> parseRange(const std::string& name) {
  static const std::regex pattern(R"(([0-9]{5,})-([0-9]{5,}))");
  std::smatch m;
  if (!std::regex_match(name, m, pattern)) return std::nullopt;
  return SceneRange{std::stoull(m[1]), std::stoull(m[2])};
}

std::uint64_t triangleCount(const json& fixture) {
  std::uint64_t n = 0;
  if (!fixture.contains("objects") || !fixture["objects"].is_array()) return 0;
  for (const json& o : fixture["objects"])
    if (o.is_object() && o.contains("mesh") && o["mesh"].is_object() &&
        o["mesh"].contains("triangles") && o["mesh"]["triangles"].is_array())
      n += o["mesh"]["triangles"].size();
  return n;
}

class Campaign {
 public:
  explicit Campaign(const CampaignArgs& args)
      : args_(args),
        scene_options_(campaignSceneOptions(args)),
        jobs_(args.jobs > 0 ? args.jobs
                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))),
        folder_(fs::absolute(args.out).lexically_normal(), identity(), args.command_line),
        exe_(selfExecutable().string()),
        expectations_(expectationsFromArgument(args.expectations)) {}

  int run() {
    const auto start = Clock::now();
    scenes_ = folder_.ensureScenes(scene_options_);
    for (const CampaignScene& s : scenes_) scene_of_[s.name] = &s;
    readFinishedRuns();
    readFinishedFailures();
    if (folder_.resumed()) {
      status_.note(fmt::format(
          "continuing the campaign in {}: {} of {} scenes already run, {} of {} failures "
          "already reduced and probed",
          folder_.dir().string(), scenesDone(), scenes_.size(), done_.size(), failures_.size()));
    } else {
      status_.note(fmt::format("starting a campaign in {}: {} scenes x {} against {}",
                               folder_.dir().string(), scenes_.size(),
                               fmt::join(args_.backends, ", "), args_.against));
    }
    runScenes();
    if (!interrupt_.interrupted()) reduceFailures();
    if (!interrupt_.interrupted()) probeFailures();
    status_.clear();
    const int code = writeSummary();
    if (interrupt_.interrupted()) {
      status_.note(fmt::format(
          "interrupted after {}: kept {} of {} scenes run and {} of {} failures reduced; run "
          "the same command again to continue",
          durationText(secondsSince(start)), scenesDone(), scenes_.size(), done_.size(),
          failures_.size()));
      folder_.removeWork();
      interrupt_.reraise();
    }
    return code;
  }

 private:
  json identity() const {
    return {{"mode", "failures"},
            {"seed", scene_options_.seed},
            {"profile", toString(scene_options_.profile)},
            {"max_size", fmt::format("{}x{}", scene_options_.max_width, scene_options_.max_height)},
            {"meshes", scene_options_.mesh_root.string()},
            {"backends", args_.backends},
            {"against", args_.against},
            {"tolerance", args_.tolerance},
            {"batch", args_.batch}};
  }

  fs::path runsDir() const { return folder_.dir() / "runs"; }
  fs::path failureDir(const CampaignFailure& f) const { return folder_.dir() / "failures" / f.id; }

  std::uint64_t scenesDone() const {
    std::uint64_t n = 0;
    for (const SceneRange& r : finished_runs_) n += r.last - r.first + 1;
    return n;
  }

  std::vector<std::string> toleranceArgs() const {
    std::vector<std::string> out;
    for (const std::string& t : args_.tolerance) {
      out.emplace_back("-t");
      out.push_back(t);
    }
    if (!args_.expectations.empty()) {
      out.emplace_back("--expectations");
      out.push_back(args_.expectations);
    }
    return out;
  }

  // ---- runs ----

  void readFinishedRuns() {
    std::error_code ec;
    if (!fs::is_directory(runsDir(), ec)) return;
    std::vector<std::pair<SceneRange, fs::path>> found;
    for (const auto& e : fs::directory_iterator(runsDir(), ec)) {
      const auto range = parseRange(e.path().filename().string());
      if (range && fs::exists(e.path() / "report.json", ec)) found.emplace_back(*range, e.path());
    }
    std::sort(found.begin(), found.end(),
              [](const auto& a, const auto& b) { return a.first.first < b.first.first; });
    for (const auto& [range, path] : found) {
      if (range.last >= scenes_.size()) continue;  // a larger campaign's: not counted now
      addRun(range, path);
    }
  }

  void addRun(const SceneRange& range, const fs::path& dir) {
    const json report = readJson(dir / "report.json");
    const std::string rel = folder_.rel(dir).generic_string();
    if (report.contains("variants") && report["variants"].is_object() &&
        !report["variants"].empty())
      variants_ = report["variants"];
    countReport(report, counts_);
    for (CampaignFailure& f : failuresOfReport(
             report, rel,
             [&](const std::string& name) {
               const auto it = scene_of_.find(name);
               return it == scene_of_.end()
                          ? FixtureInfo{}
                          : FixtureInfo{it->second->file.string(), it->second->tags};
             },
             (dir / "report.json").string(), &expectations_))
      failures_.push_back(std::move(f));
    finished_runs_.push_back(range);
    run_names_.push_back(rel);
  }

  std::vector<SceneRange> pendingRanges() const {
    std::vector<bool> done(scenes_.size(), false);
    for (const SceneRange& r : finished_runs_)
      for (std::uint64_t i = r.first; i <= r.last; ++i) done[i] = true;
    std::vector<SceneRange> out;
    for (std::uint64_t i = 0; i < scenes_.size(); ++i) {
      if (done[i]) continue;
      if (!out.empty() && out.back().last + 1 == i &&
          out.back().last - out.back().first + 1 < static_cast<std::uint64_t>(args_.batch)) {
        out.back().last = i;
      } else {
        out.push_back({i, i});
      }
    }
    return out;
  }

  void runScenes() {
    const std::vector<SceneRange> pending = pendingRanges();
    for (const SceneRange& range : pending) {
      if (interrupt_.interrupted()) return;
      const fs::path staging = runsDir() / ("." + range.name() + ".partial");
      std::error_code ec;
      fs::remove_all(staging, ec);
      fs::create_directories(runsDir(), ec);
      Job job;
      job.argv = {exe_, "run"};
      for (std::uint64_t i = range.first; i <= range.last; ++i)
        job.argv.push_back(scenes_[i].file.string());
      job.argv.insert(job.argv.end(),
                      {"--backends", fmt::format("{}", fmt::join(args_.backends, ",")), "--against",
                       args_.against, "--out", staging.string(), "--jobs", std::to_string(jobs_)});
      if (!variants_.is_null()) job.argv.emplace_back("--no-variants");
      for (const std::string& t : toleranceArgs()) job.argv.push_back(t);
      job.log = runsDir() / ("." + range.name() + ".log");
      job.env = folder_.childEnv();
      std::vector<Job> jobs{job};
      const auto start = Clock::now();
      auto tick = [&] {
        const std::uint64_t done = scenesDone();
        status_.show(fmt::format(
            "campaign: scenes {}/{} ({:.0f} %), {} failures; running {}..{} ({}); ETA {}", done,
            scenes_.size(), 100.0 * static_cast<double>(done) / scenes_.size(), failures_.size(),
            range.first, range.last, durationText(secondsSince(start)), etaText(progress())));
      };
      tick();
      runCampaignJobs(jobs, 1, interrupt_, tick);
      if (jobs[0].cancelled || interrupt_.interrupted()) {
        fs::remove_all(staging, ec);
        fs::remove(job.log, ec);
        // The run was ended by a signal: its report folder's staging folder is left beside
        // `staging` (it is made when the run starts), unlocked now that the run is gone.
        removeDeadStaging(runsDir());
        return;
      }
      const int code = jobs[0].exit_code;
      if ((code != kExitPass && code != kExitFail && code != kExitBackend) ||
          !fs::exists(staging / "report.json", ec)) {
        fs::remove_all(staging, ec);
        const std::string why = lastLogLine(job.log);
        const std::string message =
            fmt::format("`rastercheck run` of scenes {}..{} exited {}: {} (log: {})", range.first,
                        range.last, code, why.empty() ? "no message" : why, job.log.string());
        if (code == kExitInput) throw InputError(message);
        throw BackendError(message);
      }
      // Frames are the bulk of a run (EXR files for every render) and everything the
      // summary links to is in pairs/: keep the reports and pair images only.
      fs::remove_all(staging / "frames", ec);
      fs::rename(job.log, staging / "run.log", ec);
      const fs::path final_dir = runsDir() / range.name();
      fs::remove_all(final_dir, ec);
      fs::rename(staging, final_dir, ec);
      if (ec)
        throw InputError(
            fmt::format("{}: cannot move into place: {}", final_dir.string(), ec.message()));
      scenes_measured_ += range.last - range.first + 1;
      scene_seconds_ += secondsSince(start);
      addRun(range, final_dir);
    }
  }

  // ---- failures: reduce, then probe ----

  void readFinishedFailures() {
    std::error_code ec;
    for (const CampaignFailure& f : failures_) {
      const fs::path record = failureDir(f) / "failure.json";
      if (!fs::exists(record, ec)) continue;
      CampaignFailure& done = done_[f.id] =
          campaignFailureFromJson(readJson(record), record.string());
      done.known = f.known;  // the expectations file as it is now, not as it was then
    }
  }

  // Failures found in later runs are read as runs finish; this picks up the records.
  std::vector<const CampaignFailure*> pendingFailures() const {
    std::vector<const CampaignFailure*> out;
    for (const CampaignFailure& f : failures_)
      if (!done_.contains(f.id)) out.push_back(&f);
    return out;
  }

  CampaignProgress progress() const {
    CampaignProgress p;
    p.scenes_left = scenes_.size() - scenesDone();
    p.scenes_done = scenes_measured_;
    p.scene_seconds = scene_seconds_;
    p.scenes_done_total = scenesDone();
    p.failures_found = failures_.size();
    p.failures_left = failures_.size() - done_.size();
    p.failures_done = failures_measured_;
    p.failure_seconds = failure_seconds_;
    p.reduce_cap_seconds = args_.reduce_seconds;
    p.parallel = jobs_;
    return p;
  }

  std::string etaText(const CampaignProgress& p) const {
    const std::optional<double> left = secondsLeft(p);
    return left ? durationText(*left) : std::string("--");
  }

  void writeReduceRecord(const CampaignFailure& f, const json& record) {
    writeFileAtomically(failureDir(f) / "reduce.json", record.dump(2) + "\n");
  }

  void reduceFailures() {
    std::vector<const CampaignFailure*> todo;
    std::error_code ec;
    for (const CampaignFailure* f : pendingFailures()) {
      if (f->cls == "error") {
        CampaignFailure done = *f;
        done.reduction = "skipped";
        fs::create_directories(failureDir(*f), ec);
        writeFileAtomically(failureDir(*f) / "failure.json", toJson(done).dump(2) + "\n");
        done_[f->id] = done;
        continue;
      }
      if (fs::exists(failureDir(*f) / "reduce.json", ec)) continue;
      fs::create_directories(failureDir(*f), ec);
      if (args_.reduce_seconds <= 0.0) {
        writeReduceRecord(*f, {{"status", "skipped"}, {"note", "--reduce-seconds 0"}});
        continue;
      }
      // A known difference is already pinned by its entry's reduced fixture: reducing a
      // couple per entry, backend and class gives its group a reproducer; reducing
      // hundreds (softpipe's d16 step fails most d16 scenes) would only cost hours.
      if (!f->known.empty()) {
        int& reduced = known_reduced_[f->known + "|" + f->actual + "|" + f->cls];
        if (reduced >= kKnownReductions) {
          writeReduceRecord(*f, {{"status", "skipped"},
                                 {"note", fmt::format("covered by {}; {} of its failures were "
                                                      "reduced",
                                                      f->known, kKnownReductions)}});
          continue;
        }
        ++reduced;
      }
      todo.push_back(f);
    }
    if (todo.empty()) return;
    std::vector<Job> jobs;
    for (const CampaignFailure* f : todo) {
      Job job;
      fs::remove(failureDir(*f) / "reduced.json", ec);
      job.argv = {exe_,
                  "reduce",
                  f->fixture_file,
                  "--expected",
                  f->expected,
                  "--actual",
                  f->actual,
                  "--class",
                  f->cls,
                  "--timeout",
                  fmt::format("{}", args_.reduce_seconds),
                  "--out",
                  (failureDir(*f) / "reduced.json").string()};
      for (const std::string& t : toleranceArgs()) job.argv.push_back(t);
      job.log = failureDir(*f) / "reduce.log";
      job.env = folder_.childEnv();
      jobs.push_back(std::move(job));
    }
    const auto start = Clock::now();
    std::size_t finished = 0;
    auto tick = [&] {
      status_.show(
          fmt::format("campaign: reducing failure {}/{} ({} at a time, up to {} each); "
                      "{} so far; ETA {}",
                      std::min(finished + 1, todo.size()), todo.size(), jobs_,
                      durationText(args_.reduce_seconds), durationText(secondsSince(start)),
                      etaText(progress())));
    };
    tick();
    runCampaignJobs(jobs, jobs_, interrupt_, tick, [&](std::size_t i) {
      const CampaignFailure& f = *todo[i];
      const Job& job = jobs[i];
      ++finished;
      if (job.cancelled) {
        fs::remove(failureDir(f) / "reduced.json", ec);
        return;
      }
      std::ifstream in(job.log);
      std::string line, text;
      bool timed_out = false;
      while (std::getline(in, line)) {
        if (line.rfind("reduce [", 0) == 0) continue;  // progress notes
        timed_out = timed_out || line.find("timed out after") != std::string::npos;
        if (!line.empty()) text += (text.empty() ? "" : "; ") + line;
      }
      json record = {{"exit_code", job.exit_code}, {"note", text}};
      if (job.exit_code == kExitPass && fs::exists(failureDir(f) / "reduced.json", ec)) {
        record["status"] = timed_out ? "timed_out" : "reduced";
      } else {
        record["status"] = "failed";
        record["note"] = fmt::format("reduce exited {}: {}", job.exit_code, lastLogLine(job.log));
      }
      writeReduceRecord(f, record);
      // The wall time per reduction at this parallelism, for the ETA.
      ++failures_measured_;
      failure_seconds_ = secondsSince(start);
    });
  }

  struct ProbeSet {
    const CampaignFailure* failure;
    json reduce;    // reduce.json
    fs::path base;  // the fixture probed (reduced, or the original)
    bool reduced;   // base is the reduced fixture
    std::vector<Probe> probes;
  };

  void probeFailures() {
    std::vector<const CampaignFailure*> todo;
    std::error_code ec;
    for (const CampaignFailure* f : pendingFailures())
      if (fs::exists(failureDir(*f) / "reduce.json", ec)) todo.push_back(f);
    if (todo.empty()) return;
    // One `run` per chunk of failures of the same pair of SPECs.
    std::stable_sort(todo.begin(), todo.end(), [](const auto* a, const auto* b) {
      return std::tie(a->actual, a->expected) < std::tie(b->actual, b->expected);
    });
    constexpr std::size_t kChunk = 8;
    const auto start = Clock::now();
    std::size_t chunks_done = 0;
    const std::size_t chunks_total = (todo.size() + kChunk - 1) / kChunk;
    for (std::size_t at = 0; at < todo.size() && !interrupt_.interrupted();) {
      std::size_t end = at + 1;
      while (end < todo.size() && end - at < kChunk && todo[end]->actual == todo[at]->actual &&
             todo[end]->expected == todo[at]->expected)
        ++end;
      probeChunk({todo.begin() + static_cast<std::ptrdiff_t>(at),
                  todo.begin() + static_cast<std::ptrdiff_t>(end)},
                 [&] {
                   const std::string eta =
                       chunks_done == 0
                           ? std::string("--")
                           : durationText(secondsSince(start) / static_cast<double>(chunks_done) *
                                          static_cast<double>(chunks_total - chunks_done));
                   status_.show(fmt::format(
                       "campaign: probing failures {}..{} of {}; {} so far; ETA {}", at + 1, end,
                       todo.size(), durationText(secondsSince(start)), eta));
                 });
      ++chunks_done;
      at = end;
    }
  }

  void probeChunk(const std::vector<const CampaignFailure*>& chunk,
                  const std::function<void()>& tick) {
    std::error_code ec;
    const fs::path work = folder_.work() / fmt::format("probes-{}", probe_runs_++);
    fs::remove_all(work, ec);
    std::vector<ProbeSet> sets;
    std::vector<std::string> files;
    for (const CampaignFailure* f : chunk) {
      ProbeSet set{f, readJson(failureDir(*f) / "reduce.json"), {}, false, {}};
      const fs::path reduced = failureDir(*f) / "reduced.json";
      set.reduced = set.reduce.value("status", std::string()) != "failed" &&
                    set.reduce.value("status", std::string()) != "skipped" &&
                    fs::exists(reduced, ec);
      set.base = set.reduced ? reduced : fs::path(f->fixture_file);
      json fixture = readJson(set.base);
      absolutizePaths(fixture, fs::absolute(set.base).parent_path());
      fixture["name"] = f->id;  // unique in the probe run, whatever the fixture's name
      set.probes = makeProbes(fixture, f->cls);
      for (std::size_t k = 0; k < set.probes.size(); ++k) {
        const fs::path file = work / f->id / fmt::format("probe-{:02}.json", k);
        fs::create_directories(file.parent_path(), ec);
        writeFileAtomically(file, readableJson(set.probes[k].fixture));
        files.push_back(file.string());
      }
      sets.push_back(std::move(set));
    }
    Job job;
    job.argv = {exe_, "run"};
    job.argv.insert(job.argv.end(), files.begin(), files.end());
    job.argv.insert(job.argv.end(), {"--backends", chunk.front()->actual, "--against",
                                     chunk.front()->expected, "--out", (work / "run").string(),
                                     "--jobs", std::to_string(jobs_), "--no-variants"});
    for (const std::string& t : toleranceArgs()) job.argv.push_back(t);
    job.log = work / "run.log";
    job.env = folder_.childEnv();
    std::vector<Job> jobs{job};
    tick();
    runCampaignJobs(jobs, 1, interrupt_, tick);
    if (jobs[0].cancelled || interrupt_.interrupted()) return;
    // Rows by fixture name; a missing report (the run refused its input) leaves every
    // probe unknown, which the failure records say.
    std::map<std::string, json> rows;
    std::string run_problem;
    if (fs::exists(work / "run" / "report.json", ec)) {
      const json report = readJson(work / "run" / "report.json");
      if (report.contains("results") && report["results"].is_array())
        for (const json& row : report["results"])
          if (row.is_object() && row.contains("fixture") && row["fixture"].is_string())
            rows[row["fixture"].get<std::string>()] = row;
    } else {
      run_problem =
          fmt::format("the probe run exited {}: {}", jobs[0].exit_code, lastLogLine(job.log));
    }
    for (const ProbeSet& set : sets) {
      CampaignFailure f = *set.failure;
      f.reduction = set.reduce.value("status", std::string("failed"));
      f.reduce_note = set.reduce.value("note", std::string());
      f.reduced_file = folder_.rel(set.base).generic_string();
      if (!set.reduced) f.reduced_file = set.base.string();  // the original, absolute
      f.triangles = triangleCount(readJson(set.base));
      std::vector<std::optional<bool>> still;
      for (const Probe& p : set.probes) {
        const std::string name = p.fixture["name"].get<std::string>();
        const auto it = rows.find(name);
        if (it == rows.end() || it->second.value("status", "") == "error") {
          still.emplace_back(std::nullopt);
          f.probe_notes.push_back(fmt::format(
              "{}: not compared: {}", p.change,
              it == rows.end() ? run_problem : it->second.value("error", std::string())));
          continue;
        }
        const json& cls = it->second[f.cls];
        still.emplace_back(cls.is_object() && cls.value("status", "") == "fail");
      }
      f.reproduces = still.empty() ? std::nullopt : still[0];
      f.involved = involvedIn(set.probes, still);
      writeFileAtomically(failureDir(f) / "failure.json", toJson(f).dump(2) + "\n");
      done_[f.id] = f;
    }
    fs::remove_all(work, ec);
  }

  // ---- summary ----

  // groups/<id>/reproducer.json with its textures beside it (relative paths), so that the
  // folder can be attached to a bug report as it is.
  std::string copyReproducer(const CampaignGroup& g, const fs::path& groups_dir) {
    const CampaignFailure& f = *g.reproducer;
    const fs::path source = fs::path(f.reduced_file).is_absolute() ? fs::path(f.reduced_file)
                                                                   : folder_.dir() / f.reduced_file;
    json fixture = readJson(source);
    absolutizePaths(fixture, source.parent_path());
    const fs::path dir = groups_dir / g.id;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (fixture.contains("materials") && fixture["materials"].is_object()) {
      for (auto& [name, m] : fixture["materials"].items()) {
        if (!m.is_object() || !m.contains("texture") || !m["texture"].is_string()) continue;
        const fs::path texture = m["texture"].get<std::string>();
        fs::create_directories(dir / "textures", ec);
        fs::copy_file(texture, dir / "textures" / texture.filename(),
                      fs::copy_options::overwrite_existing, ec);
        if (!ec) m["texture"] = "textures/" + texture.filename().string();
      }
    }
    fixture["description"] =
        fmt::format("Reproducer of campaign group {} ({}), from {}: {}", g.id, g.signature,
                    f.fixture, fixture.value("description", std::string()));
    const fs::path file = dir / "reproducer.json";
    std::ofstream out(file);
    out << readableJson(fixture);
    out.close();
    if (!out) throw InputError(fmt::format("{}: cannot write", file.string()));
    return file.string();
  }

  int writeSummary() {
    CampaignSummary s;
    s.options = identity();
    s.options["count"] = scenes_.size();
    s.options["reduce_seconds"] = args_.reduce_seconds;
    s.command = args_.command_line;
    s.scenes_total = scenes_.size();
    s.scenes_run = scenesDone();
    s.backends = counts_;
    s.runs = run_names_;
    s.variants = variants_;
    std::vector<CampaignFailure> done;
    for (const CampaignFailure& f : failures_) {
      const auto it = done_.find(f.id);
      s.failures.push_back(it == done_.end() ? f : it->second);
      if (it != done_.end()) done.push_back(it->second);
    }
    s.failures_done = done.size();
    s.complete = s.scenes_run == s.scenes_total && done.size() == failures_.size();
    const std::vector<CampaignGroup> groups = groupFailures(done);

    // The groups folder is rebuilt whole and swapped in.
    std::error_code ec;
    const fs::path staging = folder_.dir() / ".groups.staging";
    fs::remove_all(staging, ec);
    fs::create_directories(staging, ec);
    for (const CampaignGroup& g : groups) {
      CampaignSummary::GroupFiles files;
      if (g.reproducer != nullptr) {
        copyReproducer(g, staging);
        const fs::path final_file = folder_.dir() / "groups" / g.id / "reproducer.json";
        files.reproducer = folder_.rel(final_file).generic_string();
        files.command = reproduceCommand(final_file, g.expected, g.actual, args_.tolerance,
                                         fs::path("/tmp") / ("rastercheck-repro-" + g.id));
      }
      files.expectation = expectationFor(g);
      s.group_files[g.id] = files;
    }
    const fs::path groups_dir = folder_.dir() / "groups";
    const fs::path old = folder_.dir() / ".groups.old";
    fs::remove_all(old, ec);
    if (fs::exists(groups_dir, ec)) fs::rename(groups_dir, old, ec);
    fs::rename(staging, groups_dir, ec);
    if (ec)
      throw InputError(
          fmt::format("{}: cannot move into place: {}", groups_dir.string(), ec.message()));
    fs::remove_all(old, ec);

    AtomicFileSet files;
    files.stageText(folder_.dir() / "summary.md", summaryMarkdown(s, groups));
    files.stageText(folder_.dir() / "summary.json", summaryJson(s, groups).dump(2) + "\n");
    files.stageText(folder_.dir() / "index.html", indexHtml(s, groups));
    files.commit();

    for (const CampaignGroup& g : groups) {
      std::cout << fmt::format("{} {} failure{}: {}\n", g.id, g.failures.size(),
                               g.failures.size() == 1 ? "" : "s", g.signature);
      if (const auto& c = s.group_files[g.id].command; !c.empty())
        std::cout << "  reproduce: " << c << '\n';
    }
    for (const auto& [backend, c] : s.backends)
      std::cout << fmt::format("{}: {} pairs, {} pass, {} warn, {} fail, {} error{}\n", backend,
                               c.total(), c.pass, c.warn, c.fail, c.error,
                               c.flake ? fmt::format(", {} flake", c.flake) : std::string());
    std::cout << fmt::format("{} of {} scenes, {} failures in {} groups{}\n", s.scenes_run,
                             s.scenes_total, failures_.size(), groups.size(),
                             s.complete ? "" : " (incomplete)");
    std::cout << "summary: " << (folder_.dir() / "summary.md").string() << '\n';
    const int code = campaignExitCode(s, groups);
    std::cout << (code == kExitBackend ? "ERROR" : code == kExitFail ? "FAILURE" : "PASS") << '\n';
    return code;
  }

  // A group is covered when every one of its failures is known: the expectations file as
  // it is now, applied to the report of the run that found it (failuresOfReport); the
  // entry ids are named. A group with any unmarked failure is not covered.
  static ExpectationVerdict expectationFor(const CampaignGroup& g) {
    ExpectationVerdict v;
    v.checked = true;
    std::set<std::string> ids;
    for (const CampaignFailure* f : g.failures) {
      if (f->known.empty()) return v;
      ids.insert(f->known);
    }
    v.entry = fmt::format("{}", fmt::join(ids, ", "));
    return v;
  }

  const CampaignArgs& args_;
  const RandomSceneOptions scene_options_;
  const int jobs_;
  InterruptGuard interrupt_;
  CampaignFolder folder_;
  const std::string exe_;
  // The known differences, re-applied to every run's report when it is read (a resumed
  // campaign picks up entries added since its runs were made).
  const Expectations expectations_;
  StatusLine status_;
  std::vector<CampaignScene> scenes_;
  std::map<std::string, const CampaignScene*> scene_of_;
  std::vector<SceneRange> finished_runs_;
  std::vector<std::string> run_names_;
  std::map<std::string, BackendCounts> counts_;
  json variants_;
  std::vector<CampaignFailure> failures_;
  std::map<std::string, CampaignFailure> done_;
  std::uint64_t scenes_measured_ = 0;
  double scene_seconds_ = 0.0;
  std::uint64_t failures_measured_ = 0;  // reductions finished in this process
  double failure_seconds_ = 0.0;         // and the wall time they took
  int probe_runs_ = 0;
  // Reductions started per expectations entry, backend and class (see reduceFailures).
  static constexpr int kKnownReductions = 2;
  std::map<std::string, int> known_reduced_;
};

}  // namespace

int campaignCommand(const CampaignArgs& args) {
  if (args.mutations) return mutationCampaign(args);
  if (args.backends.empty()) throw InputError("campaign: --backends needs at least one SPEC");
  for (const std::string& b : args.backends) parseBackendSpec(b);  // usage errors first
  parseBackendSpec(args.against);
  if (!args.faults.empty()) throw InputError("--faults: only with --mutations");
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  if (!(args.reduce_seconds >= 0.0))
    throw InputError(fmt::format("--reduce-seconds: must be >= 0, got {}", args.reduce_seconds));
  if (args.batch < 1) throw InputError(fmt::format("--batch: must be >= 1, got {}", args.batch));
  Campaign campaign(args);
  return campaign.run();
}

}  // namespace rc
