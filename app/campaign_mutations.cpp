// `rastercheck campaign --mutations --seed S --count N --backends SPEC,... --out DIR`: the
// mutation study (debug/mutation_study.h). Per scene, `rastercheck worker` processes kept
// for the study draw the reference and each GL backend without fault, then each GL backend
// once per fault, the request carrying the RASTERCHECK_GL_FAULT setting (the primitive a
// fault needs is drawn from what the clean frame shows); the three comparisons of each
// (scene, backend, fault) are made here with the comparator, exactly as `compare` makes
// them. Results go to
// DIR/mutations/<first>-<last>.json per batch, renamed into place when complete, and
// DIR/mutations.md and mutations.json are written from all of them: interruptible and
// resumable like the failure campaign.
#include <algorithm>
#include <chrono>
#include <iostream>
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
#include "app/worker_pool.h"
#include "compare/atomic_file.h"
#include "compare/compare.h"
#include "compare/report.h"
#include "debug/mutation_study.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/scene_logic.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

std::set<std::string> failingClasses(const PairResult& r) {
  std::set<std::string> out;
  if (r.visibility.status == Status::Fail) out.insert("visibility");
  if (r.depth.status == Status::Fail) out.insert("depth");
  if (r.shading.status == Status::Fail) out.insert("shading");
  return out;
}

// What the scene offers the faults: its state and materials (the clean frame adds the
// visible primitives).
MutationScene sceneFacts(const Scene& multi) {
  // A multi-pass scene's frame pass: what the compared frame draws, with its ids.
  const Scene frame_pass =
      multi.passes.empty() ? Scene{} : passScene(multi, multi.passes.size() - 1);
  const Scene& scene = multi.passes.empty() ? multi : frame_pass;
  MutationScene m;
  m.depth_format = toString(scene.state.depth_format);
  for (const Object& o : scene.objects) {
    const Material& mat = scene.materials[o.material];
    if (primitiveCount(o) == 0) continue;
    m.textured = m.textured || mat.texture != nullptr;
    m.blended = m.blended || (scene.state.blend == Blend::Alpha && mat.opacity < 1.0);
    m.lod = m.lod || (mat.texture != nullptr && lodSampling(scene.state));
    const MinFilter min = minFilter(scene.state);
    m.lod_blend = m.lod_blend ||
                  (mat.texture != nullptr &&
                   (min == MinFilter::NearestMipmapLinear || min == MinFilter::LinearMipmapLinear));
    if (mat.shadow) {
      const bool lit = std::any_of(scene.lights.begin(), scene.lights.end(),
                                   [&](const Light& l) { return l.shadow_map == mat.shadow->map; });
      m.shadowed = m.shadowed || lit;
      m.shadow_bias = m.shadow_bias || (lit && mat.shadow->bias != 0.0);
    }
  }
  for (const PrimitiveRef& p : flattenPrimitives(scene)) {
    const PrimitiveKind kind = scene.objects[p.object].primitive;
    if (isLineKind(kind)) m.line_ids.push_back(p.id);
    if (kind == PrimitiveKind::Points) m.point_ids.push_back(p.id);
  }
  for (const DrawPass& p : drawPasses(scene)) {
    if (p.primitives.empty()) continue;
    m.depth_tested = m.depth_tested || p.depth_func != DepthFunc::Always;
    m.stencil = m.stencil || p.ops.stencil.has_value();
    m.blend_function = m.blend_function || (p.blend && p.blend_function);
    m.scissor = m.scissor || p.ops.scissor.has_value();
  }
  return m;
}

std::vector<std::uint32_t> visibleIds(const Frame& frame) {
  std::set<std::uint32_t> ids(frame.id.begin(), frame.id.end());
  ids.erase(0);
  return {ids.begin(), ids.end()};
}

class MutationStudy {
 public:
  explicit MutationStudy(const CampaignArgs& args, std::vector<const MutationFault*> faults)
      : args_(args),
        faults_(std::move(faults)),
        scene_options_(campaignSceneOptions(args)),
        jobs_(args.jobs > 0 ? args.jobs
                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))),
        folder_(fs::absolute(args.out).lexically_normal(), identity(), args.command_line) {
    parseToleranceArgs(args.tolerance, cli_);
  }

  int run() {
    const auto start = Clock::now();
    scenes_ = folder_.ensureScenes(scene_options_);
    readFinished();
    if (folder_.resumed())
      status_.note(fmt::format("continuing the mutation study in {}: {} of {} scenes already done",
                               folder_.dir().string(), scenesDone(), scenes_.size()));
    else
      status_.note(fmt::format("starting a mutation study in {}: {} scenes x {} x {} faults",
                               folder_.dir().string(), scenes_.size(),
                               fmt::join(args_.backends, ", "), faults_.size()));
    for (const auto& [first, last] : pendingRanges()) {
      if (interrupt_.interrupted()) break;
      runRange(first, last);
    }
    status_.clear();
    pool_.reset();  // the workers end before their folder goes
    const int code = writeReport();
    if (!interrupt_.interrupted()) folder_.removeWork();
    if (interrupt_.interrupted()) {
      status_.note(fmt::format(
          "interrupted after {}: kept {} of {} scenes; run the same command again to continue",
          durationText(std::chrono::duration<double>(Clock::now() - start).count()), scenesDone(),
          scenes_.size()));
      folder_.removeWork();
      interrupt_.reraise();
    }
    return code;
  }

 private:
  json identity() const {
    std::vector<std::string> names;
    for (const MutationFault* f : faults_) names.emplace_back(f->name);
    return {{"mode", "mutations"},
            {"seed", scene_options_.seed},
            {"profile", toString(scene_options_.profile)},
            {"max_size", fmt::format("{}x{}", scene_options_.max_width, scene_options_.max_height)},
            {"meshes", scene_options_.mesh_root.string()},
            {"backends", args_.backends},
            {"tolerance", args_.tolerance},
            {"batch", args_.batch},
            {"faults", names}};
  }

  fs::path resultsDir() const { return folder_.dir() / "mutations"; }

  std::uint64_t scenesDone() const {
    std::uint64_t n = 0;
    for (const auto& [first, last] : finished_) n += last - first + 1;
    return n;
  }

  void readFinished() {
    static const std::regex pattern(R"(([0-9]{5,})-([0-9]{5,})\.json)");
    std::error_code ec;
    if (!fs::is_directory(resultsDir(), ec)) return;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(resultsDir(), ec)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      std::smatch m;
      const std::string name = file.filename().string();
      if (!std::regex_match(name, m, pattern)) continue;
      const std::uint64_t first = std::stoull(m[1]), last = std::stoull(m[2]);
      if (last >= scenes_.size()) continue;
      const json doc = readJson(file);
      if (!doc.is_array()) throw InputError(fmt::format("{}: must be an array", file.string()));
      for (std::size_t i = 0; i < doc.size(); ++i)
        results_.push_back(mutationResultFromJson(doc[i], fmt::format("{}[{}]", file.string(), i)));
      finished_.emplace_back(first, last);
    }
  }

  std::vector<std::pair<std::uint64_t, std::uint64_t>> pendingRanges() const {
    std::vector<bool> done(scenes_.size(), false);
    for (const auto& [first, last] : finished_)
      for (std::uint64_t i = first; i <= last; ++i) done[i] = true;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> out;
    for (std::uint64_t i = 0; i < scenes_.size(); ++i) {
      if (done[i]) continue;
      if (!out.empty() && out.back().second + 1 == i &&
          out.back().second - out.back().first + 1 < static_cast<std::uint64_t>(args_.batch))
        out.back().second = i;
      else
        out.emplace_back(i, i);
    }
    return out;
  }

  void showProgress(std::uint64_t first, std::uint64_t last, const char* stage, std::size_t done,
                    std::size_t total) {
    const std::uint64_t scenes = scenesDone();
    const std::string eta =
        measured_scenes_ == 0
            ? std::string("--")
            : durationText(measured_seconds_ / static_cast<double>(measured_scenes_) *
                           static_cast<double>(scenes_.size() - scenes));
    status_.show(fmt::format("mutations: scenes {}/{}; {}..{}: {} {}/{}; ETA {}", scenes,
                             scenes_.size(), first, last, stage, done, total, eta));
  }

  // Renders every request through the workers; nullopt when interrupted (a worker that
  // the same Ctrl-C ended has no result worth keeping).
  std::optional<std::vector<RenderOutcome>> renderStage(const std::vector<RenderRequest>& requests,
                                                        std::uint64_t first, std::uint64_t last,
                                                        const char* stage) {
    std::map<std::size_t, std::size_t> index;  // ticket -> request
    for (std::size_t k = 0; k < requests.size(); ++k) index[pool_->submit(requests[k])] = k;
    std::vector<RenderOutcome> out(requests.size());
    std::size_t finished = 0;
    while (finished < requests.size()) {
      showProgress(first, last, stage, finished, requests.size());
      if (interrupt_.interrupted()) return std::nullopt;
      for (auto& [ticket, outcome] : pool_->poll(200)) {
        out[index.at(ticket)] = std::move(outcome);
        ++finished;
      }
    }
    if (interrupt_.interrupted()) return std::nullopt;
    return out;
  }

  // One scene: the reference and each backend without fault, then each backend once per
  // fault (set for what its clean frame shows), then the three comparisons of each
  // (backend, fault). Frames stay in memory, one scene's at a time. False when interrupted.
  bool runScene(std::uint64_t i, std::uint64_t first, std::uint64_t last,
                std::vector<MutationResult>& results) {
    const fs::path& file = scenes_[i].file;
    std::vector<RenderRequest> requests{{file, "ref"}};
    for (const std::string& b : args_.backends) requests.push_back({file, b});
    std::optional<std::vector<RenderOutcome>> clean = renderStage(requests, first, last, "clean");
    if (!clean) return false;
    const RenderOutcome& ref = clean->front();

    const Scene scene = loadScene(file);
    MutationScene facts = sceneFacts(scene);
    struct Planned {
      std::string backend;
      const RenderOutcome* clean;
      const MutationFault* fault;
      std::string setting;
      std::optional<std::size_t> render;  // index into the faulted renders
    };
    std::vector<Planned> planned;
    std::vector<RenderRequest> faulted;
    for (std::size_t k = 0; k < args_.backends.size(); ++k) {
      const RenderOutcome& c = (*clean)[k + 1];
      facts.visible_ids = c.ok ? visibleIds(c.frame) : std::vector<std::uint32_t>{};
      for (const MutationFault* f : faults_) {
        Planned p{args_.backends[k], &c, f,
                  c.ok ? faultSetting(*f, facts, scene_options_.seed, i) : "", std::nullopt};
        if (!p.setting.empty() && ref.ok) {
          p.render = faulted.size();
          faulted.push_back({file, p.backend, p.setting});
        }
        planned.push_back(std::move(p));
      }
    }
    std::optional<std::vector<RenderOutcome>> bad = renderStage(faulted, first, last, "faulted");
    if (!bad) return false;

    std::map<std::string, std::set<std::string>> controls;  // per backend
    auto failure = [](const RenderOutcome& o, const std::string& what) {
      return fmt::format("{} did not render: {}", what, o.error);
    };
    for (const Planned& p : planned) {
      MutationResult r;
      r.fixture = scenes_[i].name;
      r.fixture_file = file.string();
      r.backend = p.backend;
      r.fault = p.fault->name;
      r.setting = p.setting;
      try {
        if (!ref.ok) {
          r.verdict = MutationVerdict::Error;
          r.note = failure(ref, "the reference");
        } else if (!p.clean->ok) {
          r.verdict = MutationVerdict::Error;
          r.note = failure(*p.clean, p.backend);
        } else if (p.setting.empty()) {
          r.verdict = MutationVerdict::NotApplicable;
        } else if (const RenderOutcome& b = (*bad)[*p.render]; !b.ok) {
          r.verdict = MutationVerdict::Error;
          r.note = failure(b, p.backend + " with " + p.setting);
        } else {
          const Frame& good = p.clean->frame;
          if (!controls.contains(p.backend))
            controls[p.backend] = failingClasses(
                compareFrames(ref.frame, good, ref.frame,
                              pairTolerances(ref.frame, good, scene.tolerance, cli_)));
          r.control_fails = controls[p.backend];
          const Frame seen = effectFrame(good, b.frame, ref.frame);
          r.effect_fails = failingClasses(compareFrames(
              good, seen, ref.frame, pairTolerances(good, seen, scene.tolerance, cli_)));
          PairResult detected =
              compareFrames(ref.frame, b.frame, ref.frame,
                            pairTolerances(ref.frame, b.frame, scene.tolerance, cli_));
          r.detected_fails = failingClasses(detected);
          r.verdict =
              judgeMutation(p.fault->cls, r.control_fails, r.effect_fails, r.detected_fails);
          if (r.verdict == MutationVerdict::Missed) {
            detected.fixture = r.fixture;
            detected.expected = "ref";
            detected.actual = p.backend + " with " + p.setting;
            r.note = describe(detected);
          }
        }
      } catch (const InputError& e) {
        r.verdict = MutationVerdict::Error;
        r.note = e.what();
      }
      results.push_back(std::move(r));
    }
    return true;
  }

  void runRange(std::uint64_t first, std::uint64_t last) {
    const auto start = Clock::now();
    if (!pool_) {
      WorkerPool::Options options;
      options.max_busy = jobs_;
      options.log_dir = folder_.work() / "workers";
      options.environment = folder_.childEnv();
      std::error_code ec;
      fs::create_directories(folder_.work() / "tmp", ec);
      pool_.emplace(options);
    }
    std::vector<MutationResult> results;
    for (std::uint64_t i = first; i <= last; ++i)
      if (!runScene(i, first, last, results)) return;
    json doc = json::array();
    for (const MutationResult& r : results) doc.push_back(toJson(r));
    writeFileAtomically(resultsDir() / fmt::format("{:05}-{:05}.json", first, last),
                        doc.dump(1) + "\n");
    results_.insert(results_.end(), results.begin(), results.end());
    finished_.emplace_back(first, last);
    measured_scenes_ += last - first + 1;
    measured_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
  }

  int writeReport() {
    const MutationTallies tallies = tallyMutations(results_);
    const bool complete = scenesDone() == scenes_.size();
    json options = identity();
    options["count"] = scenes_.size();
    AtomicFileSet files;
    files.stageText(
        folder_.dir() / "mutations.md",
        mutationMarkdown(tallies, args_.command_line, scenesDone(), scenes_.size(), complete));
    files.stageText(folder_.dir() / "mutations.json",
                    mutationJson(tallies, results_, args_.command_line, options, scenesDone(),
                                 scenes_.size(), complete)
                            .dump(1) +
                        "\n");
    files.commit();
    bool missed = false, errors = false;
    for (const auto& [backend, faults] : tallies) {
      for (const MutationFault* f : faults_) {
        const auto it = faults.find(f->name);
        if (it == faults.end()) continue;
        const MutationTally& t = it->second;
        const auto n = [&](MutationVerdict v) {
          const auto k = t.verdicts.find(v);
          return k == t.verdicts.end() ? std::uint64_t{0} : k->second;
        };
        missed = missed || n(MutationVerdict::Missed) > 0;
        errors = errors || n(MutationVerdict::Error) > 0;
        std::cout << fmt::format(
            "{} {}: caught {} of {} scenes where it changes a pixel beyond its allowance in "
            "{} ({:.1f} %); {} not applicable, {} no effect, {} control fails, {} errors\n",
            backend, f->name, n(MutationVerdict::Caught), t.counted(), f->cls,
            100.0 * t.caughtFraction(), n(MutationVerdict::NotApplicable),
            n(MutationVerdict::NoEffect), n(MutationVerdict::ControlFails),
            n(MutationVerdict::Error));
      }
    }
    std::cout << fmt::format("{} of {} scenes{}\n", scenesDone(), scenes_.size(),
                             complete ? "" : " (incomplete)");
    std::cout << "report: " << (folder_.dir() / "mutations.md").string() << '\n';
    const int code = errors ? kExitBackend : missed ? kExitFail : kExitPass;
    std::cout << (code == kExitBackend ? "ERROR" : code == kExitFail ? "FAILURE" : "PASS") << '\n';
    return code;
  }

  const CampaignArgs& args_;
  std::vector<const MutationFault*> faults_;
  const RandomSceneOptions scene_options_;
  const int jobs_;
  CommandLineTolerances cli_;
  InterruptGuard interrupt_;
  CampaignFolder folder_;
  StatusLine status_;
  std::vector<CampaignScene> scenes_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> finished_;
  std::vector<MutationResult> results_;
  std::optional<WorkerPool> pool_;  // one worker per backend and job, for the whole study
  std::uint64_t measured_scenes_ = 0;
  double measured_seconds_ = 0.0;
};

}  // namespace

int mutationCampaign(const CampaignArgs& args) {
  if (args.backends.empty()) throw InputError("campaign: --backends needs at least one SPEC");
  for (const std::string& b : args.backends) {
    if (parseBackendSpec(b).kind != BackendSpec::Kind::Gl)
      throw InputError(fmt::format(
          "--backends {}: the mutation study injects GL faults; name GL backends only", b));
  }
  if (args.against != "ref")
    throw InputError("--against: the mutation study compares with the reference (ref) only");
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  if (args.batch < 1) throw InputError(fmt::format("--batch: must be >= 1, got {}", args.batch));
  std::vector<const MutationFault*> faults;
  if (args.faults.empty()) {
    for (const MutationFault& f : mutationFaults()) faults.push_back(&f);
  } else {
    for (const std::string& name : args.faults) {
      const MutationFault* f = &mutationFault(name);
      if (std::find(faults.begin(), faults.end(), f) == faults.end()) faults.push_back(f);
    }
  }
  MutationStudy study(args, std::move(faults));
  return study.run();
}

}  // namespace rc
