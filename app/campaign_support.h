// What both modes of `rastercheck campaign` (app/campaign_command.cpp, the failure
// campaign; app/campaign_mutations.cpp, the mutation study) share: the campaign folder
// (its lock, its identity in campaign.json, the generated scenes, a work folder), a status
// line with an ETA on a terminal, and Ctrl-C handling that lets the current step stop
// cleanly. Library logic (signatures, groups, tallies) is in debug/.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/subprocess.h"
#include "fixtures/random_scene.h"

namespace rc {

// SIGINT and SIGTERM set a flag instead of ending the process while this object lives;
// steps check it, and runJobs (JobControl::cancel) stops the children. reraise() ends the
// process by the signal that arrived, as a shell expects of an interrupted command.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  const std::atomic<bool>& flag() const;
  bool interrupted() const { return flag().load(); }
  [[noreturn]] void reraise() const;
};

// One status line on stderr, redrawn in place; nothing at all when stderr is not a
// terminal. note() prints a line that stays (on every stderr, terminal or not).
class StatusLine {
 public:
  StatusLine();
  void show(const std::string& text);
  void clear();
  void note(const std::string& text);

 private:
  bool tty_;
  std::size_t width_ = 0;
};

// "42 s", "3 min 05 s", "1 h 02 min".
std::string durationText(double seconds);

// One generated scene of the campaign.
struct CampaignScene {
  std::uint64_t index = 0;
  std::string name;
  std::filesystem::path file;  // absolute
  std::vector<std::string> tags;
};

// The campaign folder. The constructor takes DIR's lock (another campaign on the same
// folder is refused), creates DIR or checks that it holds a campaign started with the
// same identity (every option but --count, --jobs and --reduce-seconds), records the
// command in campaign.json, and empties the work folder.
class CampaignFolder {
 public:
  CampaignFolder(std::filesystem::path dir, nlohmann::json identity, const std::string& command);
  ~CampaignFolder();
  CampaignFolder(const CampaignFolder&) = delete;
  CampaignFolder& operator=(const CampaignFolder&) = delete;

  const std::filesystem::path& dir() const { return dir_; }
  bool resumed() const { return resumed_; }
  std::filesystem::path work() const { return dir_ / ".work"; }
  std::filesystem::path rel(const std::filesystem::path& p) const;  // relative to dir()

  // Makes DIR/scenes hold exactly scenes 0 .. count-1 of `options` (regenerated through a
  // staging folder when the count or anything else differs) and lists them.
  std::vector<CampaignScene> ensureScenes(const RandomSceneOptions& options);

  // Environment for children: their scratch folders go under work().
  std::vector<std::string> childEnv() const;

  // Removes the work folder (also done by the destructor; call it before ending the
  // process by a signal, which runs no destructor).
  void removeWork() const;

 private:
  std::filesystem::path dir_;
  int lock_fd_ = -1;
  bool resumed_ = false;
};

// Writes `text` to `file` all-or-nothing (compare/atomic_file.h).
void writeFileAtomically(const std::filesystem::path& file, const std::string& text);
// Reads a JSON file; throws InputError naming it.
nlohmann::json readJson(const std::filesystem::path& file);

// Random-scene options from the campaign's arguments (seed, count, profile, max size,
// meshes); throws InputError for bad values, as `generate` does.
RandomSceneOptions campaignSceneOptions(const CampaignArgs& args);

// Runs `jobs` (at most `parallel` at a time) as the campaign's children: in their own
// process groups, stopped by `interrupt`, with `tick` called twice a second.
void runCampaignJobs(std::vector<Job>& jobs, int parallel, const InterruptGuard& interrupt,
                     const std::function<void()>& tick,
                     const std::function<void(std::size_t)>& on_done = {});

// The last non-empty line of a child's log (why it failed).
std::string lastLogLine(const std::filesystem::path& log);

}  // namespace rc
