// `rastercheck run [FIXTURES|DIRS...] --backends SPEC,... [--against SPEC] --out DIR`:
// renders every fixture with every backend, each render in its own child process
// (`rastercheck render`, so a driver crash costs one row and each process picks its own
// GL driver), then compares every backend with --against, classifying with the
// reference's uncertainty channels, and writes one report. Everything the user gave is
// checked before the first render (exit 2, nothing written); the outputs replace an
// earlier run's only once all of them are written.
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
#include "app/debug_support.h"
#include "app/paths.h"
#include "app/report_support.h"
#include "app/subprocess.h"
#include "app/variants.h"
#include "app/version.h"
#include "compare/expectations.h"
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
  ToleranceOverrides tolerance;
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

}  // namespace

int runCommand(const RunArgs& args) {
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  Expectations known;
  if (args.expectations != "none") {
    const fs::path file =
        args.expectations.empty() ? defaultExpectationsFile() : fs::path(args.expectations);
    if (!args.expectations.empty() || fs::exists(file)) known = readExpectations(file);
  }
  if (args.backends.empty()) throw InputError("run: --backends needs at least one SPEC");
  std::vector<BackendSpec> backends;
  for (const std::string& s : args.backends) backends.push_back(parseBackendSpec(s));
  const BackendSpec against = parseBackendSpec(args.against);
  std::error_code ec;
  if (fs::exists(args.out, ec) && !fs::is_directory(args.out, ec))
    throw InputError(fmt::format("{}: --out names a file; it must be a folder", args.out.string()));

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
    fixtures.push_back({fs::absolute(file), scene.name, slug, scene.tolerance});
  }
  if (fixtures.empty()) throw InputError("run: no fixtures found in the given paths");

  ReportFolder folder(args.out);
  const fs::path frames_dir = folder.staging() / "frames";
  std::vector<Job> jobs;  // fixture-major: job i renders fixture i / N with spec i % N
  std::map<std::pair<std::size_t, std::string>, std::size_t> job_of;
  for (std::size_t f = 0; f < fixtures.size(); ++f) {
    const fs::path dir = frames_dir / fixtures[f].slug;
    fs::create_directories(dir, ec);
    if (ec) throw InputError(fmt::format("{}: cannot create: {}", dir.string(), ec.message()));
    for (const std::string& spec : render_specs) {
      job_of[{f, spec}] = jobs.size();
      jobs.push_back(renderJob(fixtures[f].file, spec, dir / fixtureSlug(spec)));
    }
  }

  // Rendering: the line names the first fixture still rendering (k of N; the ones before
  // it are done) and the SPECs running for it.
  const int parallel = args.jobs > 0
                           ? args.jobs
                           : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  Progress progress;
  std::vector<std::size_t> left(fixtures.size(), render_specs.size());
  std::vector<std::set<std::string>> running(fixtures.size());
  auto showRender = [&] {
    for (std::size_t f = 0; f < fixtures.size(); ++f) {
      if (left[f] == 0) continue;
      std::string specs;
      for (const std::string& s : running[f]) specs += (specs.empty() ? "" : ", ") + s;
      progress.show(fmt::format("[{}/{}] rendering {}{}", f + 1, fixtures.size(), fixtures[f].name,
                                specs.empty() ? "" : " (" + specs + ")"));
      return;
    }
  };
  runJobs(
      jobs, parallel,
      [&](std::size_t i) {
        running[i / render_specs.size()].insert(render_specs[i % render_specs.size()]);
        showRender();
      },
      [&](std::size_t i) {
        const std::size_t f = i / render_specs.size();
        running[f].erase(render_specs[i % render_specs.size()]);
        --left[f];
        showRender();
      });

  auto frameDir = [&](std::size_t f, const std::string& spec) {
    return frames_dir / fixtures[f].slug / fixtureSlug(spec);
  };
  // A frame a child said it wrote but that cannot be read is that backend's failure.
  auto readRendered = [&](std::size_t f, const std::string& spec) {
    try {
      return readFrameDir(frameDir(f, spec));
    } catch (const InputError& e) {
      throw BackendError(fmt::format("{}: wrote an unreadable frame: {}", spec, e.what()));
    }
  };
  Report report;
  report.tool_version = kVersion;
  report.command = "run";
  // Which legal variant each GL backend follows, probed once per backend for the run.
  if (args.variants)
    report.variants = detectVariants(render_specs, args.out / "variants", parallel);
  for (std::size_t f = 0; f < fixtures.size(); ++f) {
    const FixtureEntry& fx = fixtures[f];
    progress.show(fmt::format("[{}/{}] comparing {}", f + 1, fixtures.size(), fx.name));
    const Job& against_job = jobs[job_of[{f, against.text}]];
    const Job& ref_job = jobs[job_of[{f, std::string("ref")}]];
    for (const BackendSpec& b : backends) {
      if (b.text == against.text) continue;
      const Job& job = jobs[job_of[{f, b.text}]];
      if (against_job.exit_code != 0) {
        report.results.push_back(failedRenderResult(
            fx.name, against.text, b.text,
            against.text + ": " +
                childFailure(against_job, {fx.name + ": ", against.text + ": "})));
        continue;
      }
      if (job.exit_code != 0) {
        report.results.push_back(failedRenderResult(
            fx.name, against.text, b.text, childFailure(job, {fx.name + ": ", b.text + ": "})));
        continue;
      }
      try {
        Frame expected = readRendered(f, against.text);
        const Frame actual = readRendered(f, b.text);
        // A multisampled reference samples where the driver does (its frame.json positions).
        if (expected.hasUncertainty() && against.kind == BackendSpec::Kind::Reference)
          resampleReference(expected, actual, fx.file, against.reference);
        if (expected.width != actual.width || expected.height != actual.height)
          throw BackendError(fmt::format("{} drew {}x{}, {} drew {}x{}", against.text,
                                         expected.width, expected.height, b.text, actual.width,
                                         actual.height));
        Frame ref;
        const Frame* uncertainty = &expected;
        if (!expected.hasUncertainty() && ref_job.exit_code == 0) {
          ref = readRendered(f, "ref");
          resampleReference(ref, actual, fx.file, ReferenceOptions{});
          if (ref.width != expected.width || ref.height != expected.height)
            throw BackendError(fmt::format("ref drew {}x{}, {} drew {}x{}", ref.width, ref.height,
                                           against.text, expected.width, expected.height));
          uncertainty = &ref;
        }
        // The tolerances were checked up front; an InputError from here on (a fixture
        // changed under us) ends the run with exit 2 and no report.
        const Tolerances tol = pairTolerances(expected, actual, fx.tolerance, cli);
        report.results.push_back(
            comparePair(expected, actual, *uncertainty, tol, folder.staging()));
      } catch (const BackendError& e) {
        report.results.push_back(errorResult(fx.name, against.text, b.text, e.what()));
      }
    }
  }
  progress.clear();
  applyExpectations(known, report);
  folder.commit(report);
  printSummary(report, args.out, std::cout);
  return exitCodeFor(report);
}

}  // namespace rc
