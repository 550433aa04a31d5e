// See campaign_support.h.
#include "app/campaign_support.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <fstream>
#include <iostream>

#include <fmt/format.h>

#include "compare/atomic_file.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;

// ---- interrupts ----

namespace {

std::atomic<bool> g_interrupted{false};
volatile std::sig_atomic_t g_signal = 0;
struct sigaction g_old_int {};
struct sigaction g_old_term {};

extern "C" void onInterrupt(int sig) {
  g_signal = sig;
  g_interrupted.store(true);
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_interrupted.store(false);
  struct sigaction sa {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking wait returns EINTR and sees the flag
  sigaction(SIGINT, &sa, &g_old_int);
  sigaction(SIGTERM, &sa, &g_old_term);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
}

const std::atomic<bool>& InterruptGuard::flag() const { return g_interrupted; }

void InterruptGuard::reraise() const {
  std::cout.flush();
  std::cerr.flush();
  const int sig = g_signal != 0 ? static_cast<int>(g_signal) : SIGINT;
  std::signal(sig, SIG_DFL);
  std::raise(sig);
  std::_Exit(128 + sig);  // not reached
}

// ---- the status line ----

StatusLine::StatusLine() : tty_(::isatty(STDERR_FILENO) != 0) {}

void StatusLine::show(const std::string& text) {
  if (!tty_) return;
  std::string line = text;
  if (line.size() > 118) line.resize(118);
  std::cerr << '\r' << line << std::string(width_ > line.size() ? width_ - line.size() : 0, ' ')
            << std::flush;
  width_ = line.size();
}

void StatusLine::clear() {
  if (tty_ && width_ > 0) std::cerr << '\r' << std::string(width_, ' ') << '\r' << std::flush;
  width_ = 0;
}

void StatusLine::note(const std::string& text) {
  clear();
  std::cerr << "campaign: " << text << '\n' << std::flush;
}

std::string durationText(double seconds) {
  if (!(seconds >= 0.0)) return "?";
  const long long s = std::llround(seconds);
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

// ---- files ----

void writeFileAtomically(const fs::path& file, const std::string& text) {
  AtomicFileSet files;
  files.stageText(file, text);
  files.commit();
}

json readJson(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot be read", file.string()));
  json j = json::parse(in, nullptr, false);
  if (j.is_discarded()) throw InputError(fmt::format("{}: not valid JSON", file.string()));
  return j;
}

std::string lastLogLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

RandomSceneOptions campaignSceneOptions(const CampaignArgs& args) {
  GenerateArgs g;
  g.seed = args.seed;
  g.count = args.count;
  g.max_size = args.max_size;
  g.profile = args.profile;
  g.meshes = args.meshes;
  return generateOptions(g);
}

void runCampaignJobs(std::vector<Job>& jobs, int parallel, const InterruptGuard& interrupt,
                     const std::function<void()>& tick,
                     const std::function<void(std::size_t)>& on_done) {
  JobControl control;
  control.on_tick = tick;
  control.cancel = &interrupt.flag();
  control.own_process_group = true;
  runJobs(jobs, parallel, {}, on_done, control);
}

// ---- the folder ----

namespace {

constexpr const char* kCampaignFile = "campaign.json";

// Every identity key whose value differs, described for the error message.
std::string identityDifference(const json& stored, const json& wanted) {
  std::string out;
  auto add = [&](const std::string& text) { out += (out.empty() ? "" : "; ") + text; };
  for (const auto& [key, value] : wanted.items()) {
    const json old = stored.contains(key) ? stored[key] : json(nullptr);
    if (old != value) add(fmt::format("{} was {} there, {} now", key, old.dump(), value.dump()));
  }
  for (const auto& [key, value] : stored.items())
    if (!wanted.contains(key)) add(fmt::format("{} was {} there", key, value.dump()));
  return out;
}

}  // namespace

CampaignFolder::CampaignFolder(fs::path dir, json identity, const std::string& command)
    : dir_(std::move(dir)) {
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
    throw InputError(fmt::format("{}: --out names a file; it must be a folder", dir_.string()));
  // Empty but for a lock file (a campaign stopped before writing campaign.json) is new.
  bool foreign = false;
  if (fs::is_directory(dir_, ec))
    for (const auto& e : fs::directory_iterator(dir_, ec))
      foreign = foreign || e.path().filename() != ".lock";
  if (foreign && !fs::exists(dir_ / kCampaignFile, ec))
    throw InputError(fmt::format(
        "{}: --out is a folder that `campaign` did not write (no {}); name a new or empty folder",
        dir_.string(), kCampaignFile));
  fs::create_directories(dir_, ec);
  if (ec) throw InputError(fmt::format("{}: cannot create: {}", dir_.string(), ec.message()));
  lock_fd_ = ::open((dir_ / ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0)
    throw InputError(fmt::format(
        "{}: another campaign is working in this folder; wait for it or use another folder",
        dir_.string()));
  json record = {{"format", "rastercheck-campaign-folder/1"},
                 {"identity", identity},
                 {"commands", json::array()}};
  if (fs::exists(dir_ / kCampaignFile, ec)) {
    const json stored = readJson(dir_ / kCampaignFile);
    if (!stored.is_object() || !stored.contains("identity"))
      throw InputError(fmt::format("{}: identity: missing", (dir_ / kCampaignFile).string()));
    const std::string diff = identityDifference(stored["identity"], identity);
    if (!diff.empty())
      throw InputError(fmt::format(
          "{}: holds a campaign started with other options ({}); continue it with the same "
          "options (only --count, --jobs and --reduce-seconds may change) or use another folder",
          dir_.string(), diff));
    record = stored;
    resumed_ = true;
  }
  if (!record["commands"].is_array()) record["commands"] = json::array();
  record["commands"].push_back(command);
  writeFileAtomically(dir_ / kCampaignFile, record.dump(2) + "\n");
  fs::remove_all(work(), ec);
  fs::create_directories(work() / "tmp", ec);
  if (ec) throw InputError(fmt::format("{}: cannot create: {}", work().string(), ec.message()));
}

CampaignFolder::~CampaignFolder() {
  removeWork();
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

void CampaignFolder::removeWork() const {
  std::error_code ec;
  if (const char* keep = std::getenv("RASTERCHECK_KEEP_SCRATCH"); !keep || !*keep)
    fs::remove_all(work(), ec);
}

fs::path CampaignFolder::rel(const fs::path& p) const {
  return fs::path(p).lexically_relative(dir_);
}

std::vector<std::string> CampaignFolder::childEnv() const {
  return {"TMPDIR=" + (work() / "tmp").string()};
}

std::vector<CampaignScene> CampaignFolder::ensureScenes(const RandomSceneOptions& options) {
  const fs::path scenes = dir_ / "scenes";
  std::error_code ec;
  bool current = false;
  if (fs::exists(scenes / kRandomManifest, ec)) {
    const json m = readJson(scenes / kRandomManifest);
    current = m.value("seed", json()) == json(options.seed) &&
              m.value("first", json()) == json(0) &&
              m.value("count", json()) == json(options.count) &&
              m.value("profile", json()) == json(toString(options.profile)) &&
              m.value("max_size", json()) ==
                  json(fmt::format("{}x{}", options.max_width, options.max_height)) &&
              m.value("meshes", json()) == json(options.mesh_root.string());
  }
  if (!current) {
    // Scene i is the same whatever the count: regenerating for a new count changes no file
    // a finished run read.
    const fs::path staging = work() / "scenes";
    const fs::path old = work() / "scenes-old";
    fs::remove_all(staging, ec);
    fs::create_directories(staging, ec);
    RandomSceneOptions all = options;
    all.first = 0;
    writeRandomFixtures(all, staging);
    if (fs::exists(scenes, ec)) fs::rename(scenes, old, ec);
    fs::rename(staging, scenes, ec);
    if (ec)
      throw InputError(
          fmt::format("{}: cannot move into place: {}", scenes.string(), ec.message()));
    fs::remove_all(old, ec);
  }
  std::vector<CampaignScene> out;
  out.reserve(options.count);
  for (std::uint64_t i = 0; i < options.count; ++i) {
    const RandomFixture f = makeRandomFixture(options, i);
    out.push_back({i, f.name, fs::absolute(scenes / f.file_name).lexically_normal(), f.tags});
  }
  return out;
}

}  // namespace rc
