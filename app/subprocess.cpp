// See subprocess.h: posix_spawn + waitpid, a fixed number of children at a time.
#include "app/subprocess.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "fixtures/errors.h"

namespace rc {
namespace {

namespace fs = std::filesystem;

pid_t spawn(const Job& job, bool own_process_group) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, job.log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  if (own_process_group) {
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
  }
  std::vector<char*> argv;
  argv.reserve(job.argv.size() + 1);
  for (const std::string& a : job.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::vector<std::string> env_text;
  std::vector<char*> envp;
  if (!job.env.empty()) {
    env_text = childEnvironment(job.env);
    for (std::string& e : env_text) envp.push_back(e.data());
    envp.push_back(nullptr);
  }
  pid_t pid = -1;
  const int err = posix_spawn(&pid, argv[0], &actions, &attr, argv.data(),
                              job.env.empty() ? environ : envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (err != 0) {
    throw BackendError(fmt::format("cannot start {}: {}", job.argv[0], std::strerror(err)));
  }
  return pid;
}

// Whether a process of `group` still runs: kill(2) also counts zombies, and an orphan's
// zombie lasts until the init process reaps it (seconds in some containers), long after it
// released its files. /proc/PID/stat gives each process's state and group.
bool groupHasLiveProcess(pid_t group) {
  if (::kill(-group, 0) != 0 && errno == ESRCH) return false;
  std::error_code ec;
  for (fs::directory_iterator it("/proc", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(it->path() / "stat");
    std::string stat;
    std::getline(in, stat);
    // "PID (COMM) STATE PPID PGRP ...": COMM may hold spaces and parentheses.
    const std::size_t close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream fields(stat.substr(close + 1));
    char state = 0;
    long ppid = 0;
    long pgrp = 0;
    if ((fields >> state >> ppid >> pgrp) && pgrp == group && state != 'Z' && state != 'X')
      return true;
  }
  return false;
}

// A cancelled job's children outlive it by moments: its workers get the same SIGTERM but
// die on their own time, and a child caught between posix_spawn's clone and its exec
// still shares the job's open files (a report folder's staging lock) and may still create
// its log file. The caller cleans up after the job (a campaign removes the run's staging
// folder), so wait until nothing of the job's process group runs: SIGKILL after 2 s, give
// up after 5 s.
void waitForGroup(pid_t group) {
  const auto start = std::chrono::steady_clock::now();
  bool killed = false;
  while (groupHasLiveProcess(group)) {
    const auto waited = std::chrono::steady_clock::now() - start;
    if (waited > std::chrono::seconds(5)) return;
    if (!killed && waited > std::chrono::seconds(2)) {
      ::kill(-group, SIGKILL);
      killed = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void record(Job& job, int status) {
  if (WIFEXITED(status)) {
    job.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    job.exit_code = 128 + WTERMSIG(status);
    const char* name = sigdescr_np(WTERMSIG(status));
    job.signal_name = name ? name : fmt::format("signal {}", WTERMSIG(status));
  }
}

}  // namespace

std::vector<std::string> childEnvironment(const std::vector<std::string>& extra) {
  std::vector<std::string> out;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry(*e);
    const std::string name = entry.substr(0, entry.find('='));
    bool replaced = false;
    for (const std::string& x : extra) replaced = replaced || x.substr(0, x.find('=')) == name;
    if (!replaced) out.push_back(entry);
  }
  out.insert(out.end(), extra.begin(), extra.end());
  return out;
}

void runJobs(std::vector<Job>& jobs, int parallel, const std::function<void(std::size_t)>& on_start,
             const std::function<void(std::size_t)>& on_done, const JobControl& control) {
  parallel = std::max(1, parallel);
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0;
  // Without a clock or a cancel flag to watch, block in waitpid; else poll.
  const bool poll = control.on_tick || control.cancel != nullptr;
  const auto tick = std::chrono::duration<double>(control.tick_seconds);
  auto last_tick = std::chrono::steady_clock::now();
  bool cancelling = false;
  auto cancelled = [&] { return control.cancel != nullptr && control.cancel->load(); };
  while (next < jobs.size() || !running.empty()) {
    if (!cancelling && cancelled()) {
      cancelling = true;
      for (std::size_t k = next; k < jobs.size(); ++k) jobs[k].cancelled = true;
      next = jobs.size();
      for (const auto& [pid, index] : running) {
        jobs[index].cancelled = true;
        ::kill(control.own_process_group ? -pid : pid, SIGTERM);
      }
    }
    while (!cancelling && next < jobs.size() && static_cast<int>(running.size()) < parallel) {
      running[spawn(jobs[next], control.own_process_group)] = next;
      if (on_start) on_start(next);
      ++next;
    }
    if (running.empty()) continue;
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, poll ? WNOHANG : 0);
    if (pid == 0 || (pid < 0 && errno == EINTR)) {
      if (poll) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (control.on_tick && std::chrono::steady_clock::now() - last_tick >= tick) {
          last_tick = std::chrono::steady_clock::now();
          control.on_tick();
        }
      }
      continue;
    }
    if (pid < 0) throw BackendError(fmt::format("waitpid failed: {}", std::strerror(errno)));
    auto it = running.find(pid);
    if (it == running.end()) continue;
    record(jobs[it->second], status);
    const std::size_t index = it->second;
    running.erase(it);
    if (jobs[index].cancelled && control.own_process_group) waitForGroup(pid);
    if (on_done) on_done(index);
  }
}

}  // namespace rc
