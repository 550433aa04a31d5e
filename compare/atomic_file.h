// All-or-nothing output: every file is written under a temporary name beside its target
// and renamed into place only when all files of a set were written.
#pragma once

#include <filesystem>
#include <string_view>
#include <utility>
#include <vector>

namespace rc {

// A set of files written together. stage() gives the temporary path to write (same
// folder and extension as the target, so OpenImageIO picks the same format); commit()
// renames every staged file into place; a set destroyed without commit() removes its
// temporaries.
class AtomicFileSet {
 public:
  AtomicFileSet() = default;
  AtomicFileSet(const AtomicFileSet&) = delete;
  AtomicFileSet& operator=(const AtomicFileSet&) = delete;
  ~AtomicFileSet();

  std::filesystem::path stage(const std::filesystem::path& target);
  void stageText(const std::filesystem::path& target, std::string_view text);
  void commit();

 private:
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files_;  // temp, target
  bool committed_ = false;
};

}  // namespace rc
