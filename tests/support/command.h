// Runs shell commands for the CLI-level tests: the rastercheck binary exactly as a user
// types it, with its exit code and output. Header-only, shared by every test folder.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace rc::test {

struct CommandResult {
  int code = -1;    // exit status (128 + N after signal N); -1 when it could not start
  std::string out;  // stdout (and stderr, unless it was kept apart)
  std::string err;  // stderr when kept apart
};

// Runs `command` through /bin/sh. stderr goes into `out` as well unless `separate_err`,
// in which case it is captured on its own in `err`.
inline CommandResult runShell(const std::string& command, bool separate_err = false) {
  static int counter = 0;
  const std::filesystem::path err_file =
      std::filesystem::temp_directory_path() /
      ("rc_test_err_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  const std::string cmd = command + (separate_err ? " 2>'" + err_file.string() + "'" : " 2>&1");
  CommandResult r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (separate_err) {
    std::ifstream in(err_file);
    r.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    std::error_code ec;
    std::filesystem::remove(err_file, ec);
  }
  return r;
}

}  // namespace rc::test
