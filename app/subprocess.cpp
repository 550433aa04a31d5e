// See subprocess.h: posix_spawn + waitpid, a fixed number of children at a time.
#include "app/subprocess.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <map>

#include <fmt/format.h>

#include "fixtures/errors.h"

namespace rc {
namespace {

pid_t spawn(const Job& job) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, job.log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> argv;
  argv.reserve(job.argv.size() + 1);
  for (const std::string& a : job.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) {
    throw BackendError(fmt::format("cannot start {}: {}", job.argv[0], std::strerror(err)));
  }
  return pid;
}

}  // namespace

void runJobs(std::vector<Job>& jobs, int parallel, const std::function<void(std::size_t)>& on_start,
             const std::function<void(std::size_t)>& on_done) {
  parallel = std::max(1, parallel);
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0;
  while (next < jobs.size() || !running.empty()) {
    while (next < jobs.size() && static_cast<int>(running.size()) < parallel) {
      running[spawn(jobs[next])] = next;
      if (on_start) on_start(next);
      ++next;
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw BackendError(fmt::format("waitpid failed: {}", std::strerror(errno)));
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;
    Job& job = jobs[it->second];
    if (WIFEXITED(status)) {
      job.exit_code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
      job.exit_code = 128 + WTERMSIG(status);
      const char* name = sigdescr_np(WTERMSIG(status));
      job.signal_name = name ? name : fmt::format("signal {}", WTERMSIG(status));
    }
    const std::size_t index = it->second;
    running.erase(it);
    if (on_done) on_done(index);
  }
}

}  // namespace rc
