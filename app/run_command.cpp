// `rastercheck run [FIXTURES|DIRS...] --backends SPEC,... [--against SPEC] --out DIR`:
// renders every fixture with every backend, each render in its own child process
// (`rastercheck render`, so a driver crash costs one row and each process picks its own
// GL driver), then compares every backend with --against, classifying with the
// reference's uncertainty channels, and writes one report.
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/commands.h"
#include "app/paths.h"
#include "app/report_support.h"
#include "app/subprocess.h"
#include "app/variants.h"
#include "app/version.h"
#include "compare/report.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

struct FixtureEntry {
  fs::path file;
  std::string name;
  std::string slug;  // unique folder name
};

// The last meaningful line a failed child printed, without our own prefixes.
std::string childError(const Job& job) {
  std::ifstream in(job.log);
  std::string line;
  std::string last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  for (const char* prefix :
       {"rastercheck: backend error: ", "rastercheck: error: ", "rastercheck: internal error: "}) {
    if (last.rfind(prefix, 0) == 0) last = last.substr(std::string(prefix).size());
  }
  if (!job.signal_name.empty())
    return fmt::format("crashed ({}){}", job.signal_name, last.empty() ? "" : ": " + last);
  return last.empty() ? fmt::format("exited with code {}", job.exit_code) : last;
}

class Progress {
 public:
  explicit Progress(std::size_t total) : total_(total), tty_(::isatty(STDERR_FILENO) != 0) {}
  void step(const std::string& what) {
    ++done_;
    if (!tty_) return;
    std::string line = fmt::format("[{}/{}] {}", done_, total_, what);
    if (line.size() > 100) line.resize(100);
    std::cerr << '\r' << line << std::string(width_ > line.size() ? width_ - line.size() : 0, ' ')
              << std::flush;
    width_ = line.size();
  }
  void finish() {
    if (tty_ && width_ > 0) std::cerr << '\r' << std::string(width_, ' ') << '\r' << std::flush;
  }

 private:
  std::size_t total_;
  std::size_t done_ = 0;
  std::size_t width_ = 0;
  bool tty_;
};

}  // namespace

int runCommand(const RunArgs& args) {
  ToleranceOverrides cli;
  parseToleranceArgs(args.tolerance, cli);
  if (args.backends.empty()) throw InputError("run: --backends needs at least one SPEC");
  std::vector<BackendSpec> backends;
  for (const std::string& s : args.backends) backends.push_back(parseBackendSpec(s));
  const BackendSpec against = parseBackendSpec(args.against);

  // Every SPEC rendered once per fixture: the backends, --against, and the reference
  // whose edge_dist/depth_gap classify every pair.
  std::vector<std::string> render_specs;
  auto addSpec = [&](const std::string& s) {
    if (std::find(render_specs.begin(), render_specs.end(), s) == render_specs.end())
      render_specs.push_back(s);
  };
  addSpec("ref");
  addSpec(against.text);
  for (const BackendSpec& b : backends) addSpec(b.text);

  std::vector<fs::path> inputs = args.inputs;
  if (inputs.empty()) inputs.push_back(defaultCatalogDir());
  // Validate every fixture before rendering anything: bad input exits 2 with no output.
  std::vector<FixtureEntry> fixtures;
  std::set<std::string> slugs;
  for (const fs::path& file : findFixtures(inputs)) {
    const Scene scene = loadScene(file);
    std::string slug = fixtureSlug(scene.name);
    for (int k = 2; !slugs.insert(slug).second; ++k)
      slug = fixtureSlug(scene.name) + "~" + std::to_string(k);
    fixtures.push_back({fs::absolute(file), scene.name, slug});
  }
  if (fixtures.empty()) throw InputError("run: no fixtures found in the given paths");

  const fs::path frames_dir = args.out / "frames";
  fs::create_directories(frames_dir);
  const std::string self = selfExecutable().string();
  std::vector<Job> jobs;
  std::map<std::pair<std::size_t, std::string>, std::size_t> job_of;
  for (std::size_t f = 0; f < fixtures.size(); ++f) {
    const fs::path dir = frames_dir / fixtures[f].slug;
    fs::create_directories(dir);
    for (const std::string& spec : render_specs) {
      const fs::path out = dir / fixtureSlug(spec);
      job_of[{f, spec}] = jobs.size();
      jobs.push_back(
          Job{{self, "render", fixtures[f].file.string(), "--backend", spec, "--out", out.string()},
              dir / (fixtureSlug(spec) + ".log")});
    }
  }

  const int parallel = args.jobs > 0
                           ? args.jobs
                           : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  Progress progress(jobs.size());
  runJobs(jobs, parallel, [&](std::size_t i) {
    progress.step(fmt::format("{} @ {}", fixtures[i / render_specs.size()].name,
                              render_specs[i % render_specs.size()]));
  });
  progress.finish();

  auto frameDir = [&](std::size_t f, const std::string& spec) {
    return frames_dir / fixtures[f].slug / fixtureSlug(spec);
  };
  Report report;
  report.tool_version = kVersion;
  report.command = "run";
  // Which legal variant each GL backend follows, probed once per backend for the run.
  if (args.variants)
    report.variants = detectVariants(render_specs, args.out / "variants", parallel);
  for (std::size_t f = 0; f < fixtures.size(); ++f) {
    const Job& against_job = jobs[job_of[{f, against.text}]];
    const Job& ref_job = jobs[job_of[{f, std::string("ref")}]];
    for (const BackendSpec& b : backends) {
      if (b.text == against.text) continue;
      const Job& job = jobs[job_of[{f, b.text}]];
      if (against_job.exit_code != 0) {
        report.results.push_back(errorResult(fixtures[f].name, against.text, b.text,
                                             against.text + ": " + childError(against_job)));
        continue;
      }
      if (job.exit_code != 0) {
        report.results.push_back(
            errorResult(fixtures[f].name, against.text, b.text, b.text + ": " + childError(job)));
        continue;
      }
      try {
        const Frame expected = readFrameDir(frameDir(f, against.text));
        const Frame actual = readFrameDir(frameDir(f, b.text));
        Frame ref;
        const Frame* uncertainty = &expected;
        if (!expected.hasUncertainty() && ref_job.exit_code == 0) {
          ref = readFrameDir(frameDir(f, "ref"));
          uncertainty = &ref;
        }
        report.results.push_back(comparePair(expected, actual, *uncertainty, cli, args.out));
      } catch (const InputError& e) {
        report.results.push_back(errorResult(fixtures[f].name, against.text, b.text, e.what()));
      }
    }
  }
  writeReport(report, args.out);
  printSummary(report, args.out, std::cout);
  return exitCodeFor(report);
}

}  // namespace rc
