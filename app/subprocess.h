// Child processes for `run`: each render happens in its own process, so a driver that
// crashes takes down one job, not the run, and GALLIUM_DRIVER can differ per job.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace rc {

struct Job {
  std::vector<std::string> argv;  // argv[0] is the program
  std::filesystem::path log;      // stdout and stderr of the child go here
  int exit_code = -1;             // set when finished; 128+N when killed by signal N
  std::string signal_name;        // non-empty when killed by a signal
};

// Runs the jobs in order, at most `parallel` at a time, calling on_start(index) as each
// starts and on_done(index) as each finishes (from the calling thread; either may be
// empty). Throws BackendError when a child cannot be started.
void runJobs(std::vector<Job>& jobs, int parallel,
             const std::function<void(std::size_t)>& on_start = {},
             const std::function<void(std::size_t)>& on_done = {});

}  // namespace rc
