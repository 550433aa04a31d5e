// `rastercheck run [FIXTURES|DIRS...] --backends SPEC,... [--against SPEC] --out DIR`:
// renders every fixture with every backend on long-lived workers (app/worker_pool.h: one
// process per backend and busy slot, its driver loaded once, so a driver crash or hang
// costs one row), compares every backend with --against as each fixture's frames arrive,
// classifying with the reference's uncertainty channels, and writes one report. Frames
// and pair images are written for pairs that do not pass (all with --keep-frames).
// Everything the user gave is checked before the first fixture renders (exit 2, nothing
// written; the GL workers draw the variant probes meanwhile); the outputs replace an
// earlier run's only once all of them are written. With
// --shard K/N it runs one deterministic part of the whole run (compare/shards.h).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/commands.h"
#include "app/paths.h"
#include "app/report_support.h"
#include "app/variants.h"
#include "app/version.h"
#include "app/worker_pool.h"
#include "compare/deqp_results.h"
#include "compare/expectations.h"
#include "compare/pair_images.h"
#include "compare/report.h"
#include "compare/shards.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/mesh_import.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

struct FixtureEntry {
  fs::path file;
  std::string name;
  std::string slug;  // unique folder name
  ToleranceOverrides tolerance;
  double raster = 0.0;  // rasterCost (compare/shards.h)
};

// One compared pair of the whole run: fixture, actual backend, place in the report.
struct PairPlan {
  std::size_t fixture = 0;
  std::size_t backend = 0;  // index into the backends
  std::size_t index = 0;    // row in the whole (unsharded) run's report
};

// One status line on a terminal, redrawn in place; nothing when stderr is not a tty.
class Progress {
 public:
  Progress() : tty_(::isatty(STDERR_FILENO) != 0) {}
  void show(const std::string& text) {
    if (!tty_) return;
    std::string line = text;
    if (line.size() > 110) line.resize(110);
    std::cerr << '\r' << line << std::string(width_ > line.size() ? width_ - line.size() : 0, ' ')
              << std::flush;
    width_ = line.size();
  }
  void clear() {
    if (tty_ && width_ > 0) std::cerr << '\r' << std::string(width_, ' ') << '\r' << std::flush;
    width_ = 0;
  }

 private:
  bool tty_;
  std::size_t width_ = 0;
};

// Threads that take tasks in order: the comparison threads (a fixture is compared as soon as
// all its frames are in, beside the rendering, so that the workers never wait for the
// comparator) and the thread that writes what a comparison keeps (frames and pair images:
// the image library's first load, ~0.2 s, and the encoding no longer hold up the
// comparisons behind it, and through them the workers).
class TaskQueue {
 public:
  explicit TaskQueue(int threads) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { loop(); });
  }
  TaskQueue(const TaskQueue&) = delete;
  TaskQueue& operator=(const TaskQueue&) = delete;
  // Only reached without finish() when the run is already failing: that failure wins, and
  // what is still queued is dropped (it would write into a report folder that is discarded).
  ~TaskQueue() {
    {
      const std::lock_guard lock(mutex_);
      queue_.clear();
    }
    try {
      finish();
    } catch (...) {  // NOLINT(bugprone-empty-catch)
    }
  }
  void push(std::function<void()> task) {
    {
      const std::lock_guard lock(mutex_);
      queue_.push_back(std::move(task));
    }
    ready_.notify_one();
  }
  // Tasks queued or running.
  std::size_t backlog() {
    const std::lock_guard lock(mutex_);
    return queue_.size() + active_;
  }
  // Waits for the queue to drain and the threads to end; rethrows the first failure.
  void finish() {
    {
      const std::lock_guard lock(mutex_);
      closing_ = true;
    }
    ready_.notify_all();
    for (std::thread& t : threads_)
      if (t.joinable()) t.join();
    if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
  }
  bool failed() {
    const std::lock_guard lock(mutex_);
    return failure_ != nullptr;
  }

 private:
  void loop() {
    for (;;) {
      std::function<void()> task;
      {
        std::unique_lock lock(mutex_);
        ready_.wait(lock, [&] { return closing_ || !queue_.empty(); });
        if (queue_.empty() || failure_) return;
        task = std::move(queue_.front());
        queue_.pop_front();
        ++active_;
      }
      try {
        task();
      } catch (...) {
        const std::lock_guard lock(mutex_);
        if (!failure_) failure_ = std::current_exception();
      }
      const std::lock_guard lock(mutex_);
      --active_;
    }
  }

  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::function<void()>> queue_;
  std::size_t active_ = 0;
  bool closing_ = false;
  std::exception_ptr failure_;
  std::vector<std::thread> threads_;
};

// "<fixture>: <spec>: why" as the backend says it, without what the row already names.
std::string stripNames(std::string message, const std::vector<std::string>& prefixes) {
  for (const std::string& p : prefixes)
    if (message.rfind(p, 0) == 0) message = message.substr(p.size());
  return message;
}

void writeText(const fs::path& file, const std::string& text) {
  std::error_code ec;
  fs::create_directories(file.parent_path(), ec);
  std::ofstream out(file);
  out << text;
  if (!out) throw InputError(fmt::format("{}: cannot write", file.string()));
}

// deqp-runner's caselist: one fixture name per line (blank lines and '#' lines skipped; a
// line ending in ".txt" includes that caselist, relative to this one's folder), in order.
void readCaselist(const fs::path& file, std::vector<std::pair<std::string, std::string>>& out,
                  int depth = 0) {
  if (depth > 16) throw InputError(fmt::format("{}: caselists include each other", file.string()));
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot read the caselist", file.string()));
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (line.size() > 4 && line.compare(line.size() - 4, 4, ".txt") == 0) {
      readCaselist(file.parent_path() / line, out, depth + 1);
      continue;
    }
    out.emplace_back(line, fmt::format("{}:{}", file.string(), n));
  }
}

// The fixtures a caselist names, in its order; every name must be one of `found`.
std::vector<FixtureEntry> selectCaselist(const fs::path& caselist,
                                         std::vector<FixtureEntry> found) {
  std::vector<std::pair<std::string, std::string>> names;
  readCaselist(caselist, names);
  std::map<std::string, std::size_t> by_name;
  for (std::size_t i = 0; i < found.size(); ++i) by_name.emplace(found[i].name, i);
  std::vector<FixtureEntry> out;
  std::set<std::string> taken;
  for (const auto& [name, at] : names) {
    const auto it = by_name.find(name);
    if (it == by_name.end())
      throw InputError(fmt::format("{}: no fixture named \"{}\" in the run's inputs", at, name));
    if (taken.insert(name).second) out.push_back(found[it->second]);
  }
  return out;
}

// The niceness of work done beside the renders that only the report needs.
constexpr int kBackgroundNice = 10;

// A render's time as its frame.json says (time_ms), in seconds; 0 when it does not.
double renderSeconds(const RenderOutcome& o) {
  if (!o.ok || !o.frame.meta.is_object() || !o.frame.meta.contains("time_ms") ||
      !o.frame.meta["time_ms"].is_number())
    return 0.0;
  return o.frame.meta["time_ms"].get<double>() / 1000.0;
}

}  // namespace

int runCommand(const RunArgs& args) {
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  cli.extra.flip_mean_fail = args.flip_threshold;
  {
    Tolerances check;  // a bad threshold is refused before anything renders
    applyOverrides(check, cli);
  }
  const Expectations known = expectationsFromArgument(args.expectations);
  const RunnerFiles runner = readRunnerFiles(args.baseline, args.flakes, args.skips);
  if (args.retries < -1)
    throw InputError(fmt::format("--retries {}: must be 0 or more", args.retries));
  const int retries = args.retries < 0 ? 1 : args.retries;
  if (args.backends.empty()) throw InputError("run: --backends needs at least one SPEC");
  std::vector<BackendSpec> backends;
  for (const std::string& s : args.backends) backends.push_back(parseBackendSpec(s));
  const BackendSpec against = parseBackendSpec(args.against);
  if (!(args.timeout_seconds >= 0.0))
    throw InputError(fmt::format("--timeout {}: must be a number of seconds >= 0 (0: none)",
                                 args.timeout_seconds));
  const bool sharded = !args.shard.empty();
  const ShardSpec shard = sharded ? parseShard(args.shard) : ShardSpec{};
  std::error_code ec;
  if (fs::exists(args.out, ec) && !fs::is_directory(args.out, ec))
    throw InputError(fmt::format("{}: --out names a file; it must be a folder", args.out.string()));

  std::vector<fs::path> inputs = args.inputs;
  if (inputs.empty()) inputs.push_back(defaultCatalogDir());
  // The validation below imports every mesh file once; the workers read those imports back.
  const SharedImportCache shared_meshes;
  // Validate every fixture before rendering anything: bad input exits 2 with no output.
  std::vector<FixtureEntry> fixtures;
  std::set<std::string> slugs;
  // Every render's estimate within the limits, too (the reference always renders).
  const ResourceLimits limits = ResourceLimits::current();
  const bool any_gl = against.kind == BackendSpec::Kind::Gl ||
                      std::any_of(backends.begin(), backends.end(), [](const BackendSpec& b) {
                        return b.kind == BackendSpec::Kind::Gl;
                      });
  // Renders (and, before them, fixture loads) at a time: --jobs, else one per core.
  const int parallel = args.jobs > 0
                           ? args.jobs
                           : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // The reference renders too when --against has no uncertainty channels of its own.
  const bool needs_ref = against.kind == BackendSpec::Kind::Gl;

  // The report folder and the workers come first: the GL workers start (load their drivers,
  // make their contexts) and draw the variant probes while the fixtures are checked. A bad
  // fixture still exits 2 with nothing written (the folder is only staged, and the workers
  // are ended unheard).
  ReportFolder folder(args.out);
  std::optional<WorkerPool> pool;
  pool.emplace(WorkerPool::Options{parallel, args.timeout_seconds, folder.staging() / "workers"});
  // Which legal variant each GL backend follows, probed once per backend for the run: every
  // backend the run names. With --skips or --shard a backend may be left without pairs (its
  // driver perhaps broken or hanging): the probes then wait for the fixture check, and go to
  // the backends that render, as the fixtures do.
  VariantProbes probes;
  std::vector<std::size_t> probe_tickets;
  auto probes_start = std::chrono::steady_clock::now();
  auto queueProbes = [&](const std::vector<std::string>& specs) {
    probes = prepareVariantProbes(specs, folder.staging() / "variants");
    for (const RenderRequest& r : probes.requests) probe_tickets.push_back(pool->submit(r));
    probes_start = std::chrono::steady_clock::now();
  };
  // Every backend the run names, in the order a fixture's renders are queued.
  std::vector<std::string> run_specs = {against.text};
  if (needs_ref && against.text != "ref") run_specs.emplace_back("ref");
  for (const BackendSpec& b : backends)
    if (std::find(run_specs.begin(), run_specs.end(), b.text) == run_specs.end())
      run_specs.push_back(b.text);
  const bool early_probes = args.variants && args.skips.empty() && !sharded;
  if (early_probes) queueProbes(run_specs);
  // The fixtures that have passed the check are rendered while the others are checked (the
  // workers waited ~0.2 s for the check of 200 small scenes) when the run renders every
  // fixture it finds on every backend it names (no --skips, --shard, --caselist or
  // --fraction); their frames wait in memory for the check's end, so at most kEarlyFixtures
  // whose frames come to kEarlyBytes (estimated: ~100 bytes a sample for the reference's
  // planes, ~30 for a GL driver's).
  const bool early_renders = args.skips.empty() && !sharded && args.caselist.empty() &&
                             args.fraction == 1 && args.fraction_start == 1;
  constexpr std::size_t kEarlyFixtures = 64;
  constexpr std::size_t kEarlyBytes = std::size_t{256} << 20;
  std::size_t bytes_per_sample = 0;
  for (const std::string& spec : run_specs)
    bytes_per_sample += parseBackendSpec(spec).kind == BackendSpec::Kind::Reference ? 100 : 30;

  // Loaded `parallel` at a time (a mesh file's import is a child process of its own, and a
  // catalog's images and meshes are read one after another otherwise); the first fixture in
  // order that fails is the one reported, as when they were loaded one by one.
  std::vector<fs::path> files;
  struct Checked {
    FixtureEntry entry;
    std::size_t samples = 0;  // pixels x samples per pixel
    std::exception_ptr error;
  };
  std::vector<Checked> checked;
  // Where the check has come (guarded by check_mutex): per file, one of these.
  enum class CheckState : char { Unchecked, Fine, Bad, Queued /* fine, its renders queued */ };
  std::mutex check_mutex;
  std::vector<CheckState> check_state;
  auto check = [&] {
    // Not the report folder (an earlier run's variant probes are scenes too).
    files = findFixtures(inputs, {args.out});
    // The mesh files the fixtures name, imported in one importer process (prefetchMeshImports:
    // an optimisation only) while the fixtures that name none are checked; those that do
    // are checked after it, so that they find their imports made.
    std::vector<std::pair<fs::path, bool>> meshes;
    std::vector<std::size_t> order;
    std::vector<std::size_t> with_meshes;
    for (std::size_t i = 0; i < files.size(); ++i) {
      auto named = meshFilesNamed(files[i]);
      (named.empty() ? order : with_meshes).push_back(i);
      meshes.insert(meshes.end(), named.begin(), named.end());
    }
    const std::size_t first_with_meshes = order.size();
    order.insert(order.end(), with_meshes.begin(), with_meshes.end());
    std::shared_future<void> prefetched;
    if (!meshes.empty())
      prefetched = std::async(std::launch::async, [&meshes] { prefetchMeshImports(meshes); });
    checked.resize(files.size());
    {
      const std::lock_guard lock(check_mutex);
      check_state.assign(files.size(), CheckState::Unchecked);
    }
    std::atomic<std::size_t> next{0};
    auto validate = [&] {
      for (std::size_t k = next++; k < order.size(); k = next++) {
        const std::size_t i = order[k];
        // (wait() is const: threads may call it on one object, [res.on.data.races].)
        if (k >= first_with_meshes) prefetched.wait();
        try {
          const Scene scene = loadScene(files[i]);
          checkResources(scene, RendererKind::Reference, limits);
          if (any_gl) checkResources(scene, RendererKind::Gl, limits);
          checkComparison(files[i].string(), scene.width, scene.height, limits);
          checked[i].entry = {fs::absolute(files[i]), scene.name, "", scene.tolerance,
                              rasterCost(scene)};
          checked[i].samples = static_cast<std::size_t>(scene.width) * scene.height *
                               static_cast<std::size_t>(std::max(1, scene.state.samples));
        } catch (...) {
          checked[i].error = std::current_exception();
        }
        const std::lock_guard lock(check_mutex);
        check_state[i] = checked[i].error ? CheckState::Bad : CheckState::Fine;
      }
    };
    const std::size_t threads = std::min<std::size_t>(files.size(), parallel);
    std::vector<std::thread> helpers;
    for (std::size_t t = 1; t < threads; ++t) helpers.emplace_back(validate);
    validate();
    for (std::thread& t : helpers) t.join();
  };
  // The probes' outcomes that come in meanwhile (with when), taken up with the renders'.
  struct Early {
    std::size_t ticket;
    RenderOutcome outcome;
    std::chrono::steady_clock::time_point at;
  };
  std::vector<Early> early;
  // (file index, backend) -> ticket of a render queued during the check.
  std::map<std::pair<std::size_t, std::string>, std::size_t> early_tickets;
  std::size_t early_fixtures = 0;
  std::size_t early_bytes = 0;
  auto queueChecked = [&] {
    if (!early_renders) return;
    std::vector<std::pair<std::size_t, fs::path>> ready;
    {
      const std::lock_guard lock(check_mutex);
      for (std::size_t i = 0; i < check_state.size() && early_fixtures < kEarlyFixtures; ++i) {
        if (check_state[i] != CheckState::Fine) continue;
        const std::size_t bytes = checked[i].samples * bytes_per_sample;
        if (early_bytes + bytes > kEarlyBytes) continue;  // a smaller one may fit
        check_state[i] = CheckState::Queued;
        early_bytes += bytes;
        ++early_fixtures;
        ready.emplace_back(i, checked[i].entry.file);
      }
    }
    for (const auto& [i, file] : ready)
      for (const std::string& spec : run_specs)
        early_tickets[{i, spec}] = pool->submit({file, spec});
  };
  if (probe_tickets.empty() && !early_renders) {
    check();
  } else {
    std::atomic<bool> checked_all{false};
    std::exception_ptr check_error;
    std::thread checker([&] {
      try {
        check();
      } catch (...) {
        check_error = std::current_exception();
      }
      checked_all = true;
    });
    try {
      // The first poll starts the workers on the probes.
      for (bool first = true; first || !checked_all; first = false) {
        queueChecked();
        for (auto& [ticket, outcome] : pool->poll(first ? 0 : 5))
          early.push_back({ticket, std::move(outcome), std::chrono::steady_clock::now()});
      }
    } catch (...) {
      checker.join();  // a worker that cannot start: ends the run once the check is done
      throw;
    }
    checker.join();
    if (check_error) std::rethrow_exception(check_error);
  }
  for (Checked& c : checked) {
    if (c.error) std::rethrow_exception(c.error);
    std::string slug = fixtureSlug(c.entry.name);
    for (int k = 2; !slugs.insert(slug).second; ++k)
      slug = fixtureSlug(c.entry.name) + "~" + std::to_string(k);
    c.entry.slug = slug;
    fixtures.push_back(std::move(c.entry));
  }
  if (fixtures.empty()) throw InputError("run: no fixtures found in the given paths");
  if (!args.caselist.empty()) fixtures = selectCaselist(args.caselist, std::move(fixtures));
  if (args.fraction < 1 || args.fraction_start < 1)
    throw InputError(fmt::format("--fraction {} --fraction-start {}: both must be 1 or more",
                                 args.fraction, args.fraction_start));
  if (args.fraction > 1 || args.fraction_start > 1) {
    // deqp-runner's meaning: entries M, M + N, M + 2N, ... of the list (1-based).
    std::vector<FixtureEntry> part;
    for (std::size_t i = static_cast<std::size_t>(args.fraction_start - 1); i < fixtures.size();
         i += static_cast<std::size_t>(args.fraction))
      part.push_back(std::move(fixtures[i]));
    fixtures = std::move(part);
  }
  if (fixtures.empty())
    throw InputError(fmt::format("run: --fraction {} --fraction-start {} leaves no fixture",
                                 args.fraction, args.fraction_start));

  // The whole run's pairs, in report order (fixture, then backend); a shard keeps its part.
  std::vector<PairPlan> pairs;
  std::vector<std::string> skipped;  // test names --skips leaves out (compare/deqp_results.h)
  for (std::size_t f = 0; f < fixtures.size(); ++f)
    for (std::size_t b = 0; b < backends.size(); ++b) {
      if (backends[b].text == against.text) continue;
      PairResult named;
      named.fixture = fixtures[f].name;
      named.actual = backends[b].text;
      named.expected = against.text;
      if (runner.skips.matches(testName(named))) {
        skipped.push_back(testName(named));
        continue;
      }
      pairs.push_back({f, b, pairs.size()});
    }
  const std::size_t total_pairs = pairs.size();
  nlohmann::json shard_block = nlohmann::json::object();
  if (sharded) {
    std::vector<ShardUnit> units;
    units.reserve(pairs.size());
    for (const PairPlan& p : pairs)
      units.push_back(
          {p.fixture, renderCost(fixtures[p.fixture].raster, backends[p.backend].text)});
    std::vector<double> shared;
    shared.reserve(fixtures.size());
    for (const FixtureEntry& fx : fixtures)
      shared.push_back(renderCost(fx.raster, against.text) +
                       (needs_ref ? renderCost(fx.raster, "ref") : 0.0));
    const std::vector<int> plan = assignShards(units, shared, shard.count);
    std::vector<std::string> digest_parts = {against.text, std::to_string(shard.count)};
    for (const BackendSpec& b : backends) digest_parts.push_back(b.text);
    for (const std::string& t : args.tolerance) digest_parts.push_back(t);
    for (const FixtureEntry& fx : fixtures) digest_parts.push_back(fx.name);
    nlohmann::json indices = nlohmann::json::array();
    std::vector<PairPlan> mine;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (plan[i] != shard.index - 1) continue;
      mine.push_back(pairs[i]);
      indices.push_back(pairs[i].index);
    }
    pairs = std::move(mine);
    shard_block = {{"index", shard.index},
                   {"count", shard.count},
                   {"pairs", total_pairs},
                   {"plan", planDigest(digest_parts)},
                   {"pair_indices", indices}};
  }

  // What each fixture needs rendered: --against, the reference, its pairs' backends.
  std::vector<std::vector<std::string>> needed(fixtures.size());
  std::vector<std::vector<const PairPlan*>> pairs_of(fixtures.size());
  for (const PairPlan& p : pairs) {
    std::vector<std::string>& n = needed[p.fixture];
    if (n.empty()) {
      n.push_back(against.text);
      if (needs_ref && against.text != "ref") n.emplace_back("ref");
    }
    if (std::find(n.begin(), n.end(), backends[p.backend].text) == n.end())
      n.push_back(backends[p.backend].text);
    pairs_of[p.fixture].push_back(&p);
  }

  const fs::path frames_dir = folder.staging() / "frames";
  Report report;
  report.tool_version = kVersion;
  report.command = "run";
  report.shard = shard_block;
  std::vector<std::optional<PairResult>> results(pairs.size());
  {
    // The probes analysed: those of the backends that render.
    std::vector<std::string> render_specs;
    for (const auto& n : needed)
      for (const std::string& s : n)
        if (std::find(render_specs.begin(), render_specs.end(), s) == render_specs.end())
          render_specs.push_back(s);
    if (early_probes) {
      std::erase_if(probes.gl_specs, [&](const std::string& s) {
        return std::find(render_specs.begin(), render_specs.end(), s) == render_specs.end();
      });
    } else if (args.variants) {
      queueProbes(render_specs);  // first in the queue, so the workers start on them
    }
    std::vector<RenderOutcome> probe_outcomes(probe_tickets.size());
    std::size_t probes_left = probe_tickets.size();
    double probe_seconds = 0.0;
    std::future<nlohmann::json> variants_done;

    std::map<std::size_t, std::pair<std::size_t, std::string>> ticket_of;  // -> fixture, spec
    std::vector<std::map<std::string, RenderOutcome>> got(fixtures.size());
    std::vector<std::size_t> left(fixtures.size(), 0);
    for (std::size_t f = 0; f < fixtures.size(); ++f) {
      left[f] = needed[f].size();
      for (const std::string& spec : needed[f]) {
        // Queued during the check (the fixture is file f then), else now.
        const auto it = early_tickets.find({f, spec});
        const std::size_t ticket =
            it != early_tickets.end() ? it->second : pool->submit({fixtures[f].file, spec});
        if (it != early_tickets.end()) early_tickets.erase(it);
        ticket_of[ticket] = {f, spec};
      }
    }

    auto expectedFailure = [&](const PairResult& r) {
      std::string now = runnerStatus(r);
      if (r.status == Status::Fail && !knownFailuresOf(known, r).empty()) now = "ExpectedFail";
      const auto it = runner.baseline.expected.find(testName(r));
      return runnerSuccess(
          withBaseline(now, it == runner.baseline.expected.end() ? std::string() : it->second));
    };
    // Compares one pair. One that does not pass (any, with --keep-frames) gets its images:
    // their folder is taken here, in comparison order, and result.images names them; the
    // caller writes them (writePairImages with `maps`). The tolerances were checked up front;
    // an InputError from here on (a fixture changed under us) ends the run with exit 2 and no
    // report.
    struct Compared {
      PairResult result;
      ClassMaps maps;
      fs::path images;  // the pair's folder, when it gets images
    };
    auto comparePairOf = [&](const FixtureEntry& fx, const Frame& expected, const Frame& actual,
                             const Frame& uncertainty) {
      const Tolerances tol = pairTolerances(expected, actual, fx.tolerance, cli);
      Compared c;
      c.maps.want_flip = args.flip;  // --flip-threshold asks through tol as well
      c.result = compareNamed(expected, actual, uncertainty, tol, &c.maps);
      if (args.keep_frames || c.result.status != Status::Pass) {
        c.images = folder.pairDirectory(c.result);
        c.result.images = pairImageNames(c.images, true, c.maps);
      }
      return c;
    };
    // What a comparison keeps is written on the writer threads, after it (a fixture's files in
    // order: its frames before the pair images that link their color.png).
    TaskQueue writer(std::max(1, parallel / 2));
    auto compareFixture = [&](std::size_t f) {
      const FixtureEntry& fx = fixtures[f];
      // The fixture's frames, shared with the writes that need them.
      const auto held =
          std::make_shared<const std::map<std::string, RenderOutcome>>(std::move(got[f]));
      got[f].clear();
      const std::map<std::string, RenderOutcome>& outs = *held;
      const fs::path dir = frames_dir / fx.slug;
      std::set<std::string> kept;
      std::vector<std::function<void()>> writes;
      // Frames (and what the worker printed) of the renders a non-passing pair shows.
      auto keepFrame = [&](const std::string& spec) -> fs::path {
        fs::path frame_dir = dir / fixtureSlug(spec);
        if (kept.insert(spec).second) {
          writes.emplace_back([held, spec, frame_dir] {
            const RenderOutcome& o = held->at(spec);
            if (o.ok) writeFrameDir(o.frame, frame_dir);
            if (!o.log.empty()) writeText(fs::path(frame_dir) += ".log", o.log);
          });
        }
        return frame_dir;
      };
      const RenderOutcome& a = outs.at(against.text);
      for (const PairPlan* p : pairs_of[f]) {
        const std::string& spec = backends[p->backend].text;
        const RenderOutcome& b = outs.at(spec);
        PairResult r;
        if (!a.ok) {
          keepFrame(against.text);
          r = failedRenderResult(
              fx.name, against.text, spec,
              against.text + ": " + stripNames(a.error, {fx.name + ": ", against.text + ": "}));
        } else if (!b.ok) {
          keepFrame(spec);
          r = failedRenderResult(fx.name, against.text, spec,
                                 stripNames(b.error, {fx.name + ": ", spec + ": "}));
        } else {
          try {
            const Frame& actual = b.frame;
            // A multisampled reference samples where the driver does (its frame.json
            // positions): rendered again here when they differ.
            Frame resampled;
            const Frame* expected_frame = &a.frame;
            if (against.kind == BackendSpec::Kind::Reference && needsResample(a.frame, actual)) {
              resampled = a.frame;
              resampleReference(resampled, actual, fx.file, against.reference);
              expected_frame = &resampled;
            }
            const Frame& expected = *expected_frame;
            if (expected.width != actual.width || expected.height != actual.height)
              throw BackendError(fmt::format("{} drew {}x{}, {} drew {}x{}", against.text,
                                             expected.width, expected.height, spec, actual.width,
                                             actual.height));
            const Frame* uncertainty = &expected;
            const bool use_ref =
                !expected.hasUncertainty() && outs.count("ref") && outs.at("ref").ok;
            Frame resampled_ref;
            if (use_ref) {
              const Frame* ref_frame = &outs.at("ref").frame;
              if (needsResample(*ref_frame, actual)) {
                resampled_ref = *ref_frame;
                resampleReference(resampled_ref, actual, fx.file, ReferenceOptions{});
                ref_frame = &resampled_ref;
              }
              const Frame& ref = *ref_frame;
              if (ref.width != expected.width || ref.height != expected.height)
                throw BackendError(fmt::format("ref drew {}x{}, {} drew {}x{}", ref.width,
                                               ref.height, against.text, expected.width,
                                               expected.height));
              uncertainty = &ref;
            }
            Compared c = comparePairOf(fx, expected, actual, *uncertainty);
            if (!c.images.empty()) {
              // The images show the frames compared, kept beside them (their color.png is
              // the pictures' when the colours are the same).
              fs::path da = keepFrame(against.text);
              fs::path db = keepFrame(spec);
              if (use_ref) keepFrame("ref");
              std::shared_ptr<const Frame> own_expected;
              if (expected_frame == &resampled)
                own_expected = std::make_shared<const Frame>(std::move(resampled));
              writes.emplace_back([held, own_expected, against = against.text, spec,
                                   maps = std::move(c.maps), pair_dir = c.images, r = c.result,
                                   da = std::move(da), db = std::move(db)]() mutable {
                const Frame& e = own_expected ? *own_expected : held->at(against).frame;
                const Frame& drawn = held->at(spec).frame;
                writePairImages(e, drawn, maps, pair_dir, r,
                                {readyPicture(da, e), readyPicture(db, drawn)});
              });
            }
            r = std::move(c.result);
          } catch (const BackendError& e) {
            r = errorResult(fx.name, against.text, spec, e.what());
          }
        }
        r.render_seconds = renderSeconds(b);
        // A pair to render again (`--retries`), as deqp-runner reruns what fails unexpectedly
        // (not a failure an expectation or the baseline expects): its first attempt, with the
        // frames a retry is judged against kept on disk.
        if (retries > 0 && a.ok && backends[p->backend].kind == BackendSpec::Kind::Gl &&
            (r.status == Status::Fail || r.status == Status::Error) && !expectedFailure(r)) {
          keepFrame(against.text);
          if (outs.count("ref") && outs.at("ref").ok) keepFrame("ref");
          PairResult::Attempt first;
          if (b.ok) {
            first.digest = frameDigest(b.frame);
            first.frame = keepFrame(spec).string();
          } else {
            first.error = stripNames(b.error, {fx.name + ": ", spec + ": "});
          }
          r.attempts.push_back(std::move(first));
        }
        results[static_cast<std::size_t>(p - pairs.data())] = std::move(r);
      }
      if (!writes.empty()) {
        writer.push([writes = std::move(writes)] {
          for (const std::function<void()>& w : writes) w();
        });
      }
    };

    TaskQueue comparer(std::max(1, parallel / 2));
    Progress progress;
    std::size_t done = 0;
    std::size_t first_open = 0;
    std::string input_failure;
    const auto to_render = static_cast<std::size_t>(
        std::count_if(left.begin(), left.end(), [](std::size_t n) { return n > 0; }));
    // `at`: when it arrived (a probe that came in during the check is timed then).
    auto take = [&](std::size_t ticket, RenderOutcome& outcome,
                    std::chrono::steady_clock::time_point at) {
      if (const auto it = std::find(probe_tickets.begin(), probe_tickets.end(), ticket);
          it != probe_tickets.end()) {
        probe_outcomes[static_cast<std::size_t>(it - probe_tickets.begin())] = std::move(outcome);
        if (--probes_left == 0) {
          probe_seconds = std::chrono::duration<double>(at - probes_start).count();
          // Analysed (and their frames written) on a thread of its own, in the time the
          // workers leave, rather than after the renders: the reference's subpixel renders
          // and the image library's loading (~0.2 s, for frame.exr and color.png) would
          // otherwise end every run.
          variants_done = std::async(std::launch::async, [&, probe_seconds] {
            // At a low priority: it is needed only for the report, and at normal priority
            // it took time from the workers (at nice 19: gen200 x llvmpipe 1.25 -> 1.18 s).
            // Not the lowest: on a busy machine the run waits for it at the end, and an
            // image library it loads first starts its threads at its priority.
            ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), kBackgroundNice);
            return analyseVariants(probes, probe_outcomes, probe_seconds);
          });
        }
        return;
      }
      // A render queued during the check that no pair wants (a run with no pairs).
      const auto mine = ticket_of.find(ticket);
      if (mine == ticket_of.end()) return;
      // A worker that judged the fixture bad input (a file changed since it was checked)
      // ends the run as bad input does before rendering: exit 2, nothing written.
      if (outcome.input_error && input_failure.empty()) input_failure = outcome.error;
      const auto [f, spec] = mine->second;
      got[f][spec] = std::move(outcome);
      if (--left[f] == 0) {
        comparer.push([&compareFixture, f] { compareFixture(f); });
        ++done;
      }
    };
    for (Early& e : early) take(e.ticket, e.outcome, e.at);
    early.clear();
    while (pool->outstanding() > 0) {
      // Frames wait in memory until compared: do not render far ahead of the comparator.
      const bool start_more =
          comparer.backlog() + writer.backlog() < 2 * static_cast<std::size_t>(parallel) + 2;
      for (auto& [ticket, outcome] : pool->poll(start_more ? 200 : 20, start_more))
        take(ticket, outcome, std::chrono::steady_clock::now());
      if (comparer.failed() || writer.failed() || !input_failure.empty()) break;
      while (first_open < fixtures.size() && left[first_open] == 0) ++first_open;
      if (first_open < fixtures.size())
        progress.show(
            fmt::format("[{}/{}] rendering {}", done, to_render, fixtures[first_open].name));
    }
    progress.clear();
    comparer.finish();  // rethrows a comparison's InputError: exit 2, no report
    writer.finish();    // the kept frames are on disk before any retry is judged
    if (!input_failure.empty()) throw InputError(input_failure);

    // --retries: each failing or erroring GL pair rendered again, every render in a worker
    // started for it alone; judged as each arrives (its frame kept, then dropped).
    std::map<std::size_t, std::pair<std::size_t, int>> retry_of;  // ticket -> pair, attempt
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (!results[i] || results[i]->attempts.empty()) continue;
      for (int k = 1; k <= retries; ++k) {
        RenderRequest request{fixtures[pairs[i].fixture].file, backends[pairs[i].backend].text};
        request.fresh = true;
        retry_of[pool->submit(request)] = {i, k};
      }
    }
    auto judgeRetry = [&](std::size_t i, int k, const RenderOutcome& o) {
      PairResult& r = *results[i];
      const FixtureEntry& fx = fixtures[pairs[i].fixture];
      const std::string& spec = backends[pairs[i].backend].text;
      const fs::path dir = frames_dir / fx.slug;
      PairResult::Attempt attempt;
      if (!o.ok) {
        attempt.error = stripNames(o.error, {fx.name + ": ", spec + ": "});
        r.attempts.push_back(std::move(attempt));
        return;
      }
      attempt.digest = frameDigest(o.frame);
      const fs::path kept = dir / fmt::format("{}~retry{}", fixtureSlug(spec), k);
      writeFrameDir(o.frame, kept);
      attempt.frame = kept.string();
      const PairResult::Attempt& first = r.attempts.front();
      if (!first.digest.empty() && first.digest != attempt.digest && r.flake_pixels == 0) {
        int x = -1, y = -1;
        r.flake_pixels = differingPixels(readFrameDir(first.frame), o.frame, &x, &y);
        r.flake_first = {x, y};
      }
      if (first.digest.empty() && r.status == Status::Error) {
        // The first render gave no frame: the row becomes this one's comparison.
        const Frame expected = readFrameDir(dir / fixtureSlug(against.text));
        Frame ref_frame;
        if (!expected.hasUncertainty() && fs::exists(dir / "ref"))
          ref_frame = readFrameDir(dir / "ref");
        const Frame& uncertainty = ref_frame.width > 0 ? ref_frame : expected;
        Compared c = comparePairOf(fx, expected, o.frame, uncertainty);
        if (!c.images.empty()) writePairImages(expected, o.frame, c.maps, c.images, c.result);
        PairResult compared = std::move(c.result);
        compared.attempts = std::move(r.attempts);
        compared.render_seconds = r.render_seconds;
        r = std::move(compared);
      }
      r.attempts.push_back(std::move(attempt));
    };
    while (pool->outstanding() > 0) {
      for (auto& [ticket, outcome] : pool->poll(200)) {
        const auto it = retry_of.find(ticket);
        if (it != retry_of.end()) judgeRetry(it->second.first, it->second.second, outcome);
      }
    }
    for (std::optional<PairResult>& r : results) {
      if (!r || r->attempts.size() < 2) continue;
      const PairResult::Attempt& first = r->attempts.front();
      // Renders that disagree: one gave a frame and another did not, or their bits differ.
      const bool disagree =
          std::any_of(r->attempts.begin() + 1, r->attempts.end(), [&](const auto& a) {
            return a.digest.empty() != first.digest.empty() || a.digest != first.digest;
          });
      if (disagree) r->status = Status::Flake;
    }
    if (args.variants)
      report.variants = variants_done.valid()
                            ? variants_done.get()
                            : analyseVariants(probes, probe_outcomes, probe_seconds);
  }
  pool.reset();  // the workers end before the report is put in place
  for (std::optional<PairResult>& r : results) report.results.push_back(std::move(*r));
  report.skipped = std::move(skipped);
  applyExpectations(known, report);
  applyRunnerFiles(runner, report);
  folder.commit(report);
  printSummary(report, args.out, std::cout);
  return exitCodeFor(report);
}

}  // namespace rc
