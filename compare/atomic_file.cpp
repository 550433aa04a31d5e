// All-or-nothing output: see atomic_file.h.
#include "compare/atomic_file.h"

#include <unistd.h>

#include <fstream>

#include <fmt/format.h>

#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;

AtomicFileSet::~AtomicFileSet() {
  if (committed_) return;
  std::error_code ec;
  for (const auto& [temp, target] : files_) fs::remove(temp, ec);
}

fs::path AtomicFileSet::stage(const fs::path& target) {
  std::error_code ec;
  fs::create_directories(target.parent_path().empty() ? fs::path(".") : target.parent_path(), ec);
  if (ec)
    throw InputError(
        fmt::format("{}: cannot create folder: {}", target.parent_path().string(), ec.message()));
  // ".name.tmp-PID.ext": hidden, unique to this process, same extension as the target.
  fs::path temp = target.parent_path() / fmt::format(".{}.tmp-{}{}", target.stem().string(),
                                                     ::getpid(), target.extension().string());
  files_.emplace_back(temp, target);
  return temp;
}

void AtomicFileSet::stageText(const fs::path& target, std::string_view text) {
  const fs::path temp = stage(target);
  std::ofstream out(temp, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw InputError(fmt::format("{}: cannot write", target.string()));
}

void AtomicFileSet::commit() {
  // Renames cannot be undone, so refuse before the first one if any would fail for a
  // reason we can see (a folder in the way).
  for (const auto& [temp, target] : files_) {
    std::error_code ec;
    if (fs::is_directory(target, ec))
      throw InputError(fmt::format("{}: cannot write: a folder is in the way", target.string()));
  }
  for (const auto& [temp, target] : files_) {
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) throw InputError(fmt::format("{}: cannot write: {}", target.string(), ec.message()));
  }
  committed_ = true;
}

}  // namespace rc
