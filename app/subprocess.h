// Child processes for `run` and `campaign`: each render happens in its own process, so a
// driver that crashes takes down one job, not the run, and GALLIUM_DRIVER can differ per
// job.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace rc {

// This process's environment with the NAME=VALUE entries of `extra` added or replacing
// ours (what a child is started with).
std::vector<std::string> childEnvironment(const std::vector<std::string>& extra);

struct Job {
  std::vector<std::string> argv;  // argv[0] is the program
  std::filesystem::path log;      // stdout and stderr of the child go here
  int exit_code = -1;             // set when finished; 128+N when killed by signal N
  std::string signal_name;        // non-empty when killed by a signal
  std::vector<std::string> env;   // NAME=VALUE entries added to (or replacing) ours
  bool cancelled = false;  // stopped by JobControl::cancel: killed (128+15) or never started (-1)
};

// What a long-running caller (`campaign`) needs beyond running jobs to completion.
struct JobControl {
  // Called about every tick_seconds while children run (a progress line's clock).
  std::function<void()> on_tick;
  double tick_seconds = 0.5;
  // When it becomes true: no further job starts, and every running child's process group
  // gets SIGTERM; its job is marked cancelled. runJobs returns once they have exited
  // (with own_process_group: once their groups are empty, what they started gone too).
  const std::atomic<bool>* cancel = nullptr;
  // Each child leads its own process group, so that a terminal's Ctrl-C reaches only
  // this process (which then stops the children through `cancel`) and SIGTERM to the
  // group also stops the child's own children.
  bool own_process_group = false;
};

// Runs the jobs in order, at most `parallel` at a time, calling on_start(index) as each
// starts and on_done(index) as each finishes (from the calling thread; either may be
// empty). Throws BackendError when a child cannot be started.
void runJobs(std::vector<Job>& jobs, int parallel,
             const std::function<void(std::size_t)>& on_start = {},
             const std::function<void(std::size_t)>& on_done = {}, const JobControl& control = {});

}  // namespace rc
