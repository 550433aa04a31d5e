// The rastercheck subcommands. Each returns the process exit code (fixtures/errors.h)
// and throws InputError / BackendError for the caller to report in one line.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace rc {

struct RenderArgs {
  std::filesystem::path scene;
  std::string backend = "ref";
  std::filesystem::path out;
};
int renderCommand(const RenderArgs& args);

struct ListArgs {
  std::vector<std::filesystem::path> paths;
  bool json = false;
  bool markdown = false;
};
int listCommand(const ListArgs& args);

}  // namespace rc
