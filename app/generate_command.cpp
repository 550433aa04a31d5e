// `rastercheck generate --seed S --count N --out DIR`: reproducible random fixtures
// (fixtures/random_scene.h), written all-or-nothing through a staging folder beside DIR.
#include <unistd.h>

#include <charconv>
#include <iostream>
#include <limits>
#include <regex>

#include <fmt/format.h>

#include "app/commands.h"
#include "fixtures/errors.h"
#include "fixtures/random_scene.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

// A folder written all-or-nothing: everything goes into `.<name>.staging-<pid>` beside
// `out`; commit() swaps it into place (an earlier generated folder is replaced whole);
// destroyed without commit(), it removes the staging folder and `out` stays as it was.
// Kept small so that a shared atomic-folder mechanism can take its place.
class StagedFolder {
 public:
  explicit StagedFolder(fs::path out) : out_(std::move(out)) {
    std::error_code ec;
    if (fs::exists(out_, ec) && !fs::is_directory(out_, ec))
      throw InputError(fmt::format("{}: --out names a file; it must be a folder", out_.string()));
    if (fs::is_directory(out_, ec) && !fs::is_empty(out_, ec) &&
        !fs::exists(out_ / kRandomManifest, ec))
      throw InputError(fmt::format(
          "{}: --out is a folder that `generate` did not write (no {}); name a new or empty "
          "folder",
          out_.string(), kRandomManifest));
    fs::create_directories(out_.parent_path(), ec);
    staging_ = sibling("staging");
    fs::remove_all(staging_, ec);
    if (!fs::create_directory(staging_, ec) || ec)
      throw InputError(
          fmt::format("{}: cannot create the output folder: {}", staging_.string(), ec.message()));
  }
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;
  ~StagedFolder() {
    std::error_code ec;
    if (!committed_) fs::remove_all(staging_, ec);
  }

  const fs::path& path() const { return staging_; }

  void commit() {
    std::error_code ec;
    const fs::path old = sibling("old");
    const bool replacing = fs::exists(out_, ec);
    if (replacing) {
      fs::remove_all(old, ec);
      fs::rename(out_, old, ec);
      if (ec) throw InputError(fmt::format("{}: cannot replace: {}", out_.string(), ec.message()));
    }
    fs::rename(staging_, out_, ec);
    if (ec) {
      std::error_code undo;
      if (replacing) fs::rename(old, out_, undo);
      throw InputError(fmt::format("{}: cannot move into place: {}", out_.string(), ec.message()));
    }
    committed_ = true;
    if (replacing) fs::remove_all(old, ec);
  }

 private:
  fs::path sibling(const char* what) const {
    return out_.parent_path() /
           fmt::format(".{}.{}-{}", out_.filename().string(), what, ::getpid());
  }

  fs::path out_;
  fs::path staging_;
  bool committed_ = false;
};

// A decimal in [0, 2^64 - 1], digits only.
std::uint64_t parseUnsigned(const std::string& text, const char* option) {
  std::uint64_t v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end)
    throw InputError(fmt::format("{}: expected an integer in [0, 18446744073709551615], got '{}'",
                                 option, text));
  return v;
}

}  // namespace

int generateCommand(const GenerateArgs& args) {
  RandomSceneOptions options;
  options.seed = parseUnsigned(args.seed, "--seed");
  options.first = parseUnsigned(args.first, "--first");
  if (args.count < 1 || args.count > 1'000'000)
    throw InputError(fmt::format("--count: must be in [1, 1000000], got {}", args.count));
  options.count = static_cast<std::uint64_t>(args.count);
  if (options.first > std::numeric_limits<std::uint64_t>::max() - options.count)
    throw InputError("--first: first + count goes beyond 2^64 - 1");
  std::smatch m;
  if (!std::regex_match(args.max_size, m, std::regex(R"(([0-9]{1,5})x([0-9]{1,5}))")))
    throw InputError(
        fmt::format("--max-size: expected WxH (e.g. 200x150), got '{}'", args.max_size));
  options.max_width = std::stoi(m[1]);
  options.max_height = std::stoi(m[2]);
  if (options.max_width < 1 || options.max_height < 1 || options.max_width > 16384 ||
      options.max_height > 16384)
    throw InputError(
        fmt::format("--max-size: each side must be in [1, 16384], got '{}'", args.max_size));
  options.profile = parseRandomProfile(args.profile);
  if (!args.meshes.empty()) options.mesh_root = fs::absolute(args.meshes).lexically_normal();
  checkRandomMeshFiles(options);

  // "DIR/" and "DIR/." name DIR itself.
  fs::path out = fs::absolute(args.out).lexically_normal();
  if (!out.has_filename()) out = out.parent_path();
  if (out == out.root_path()) throw InputError("--out: cannot be the root folder");
  StagedFolder folder(out);
  writeRandomFixtures(options, folder.path());
  folder.commit();
  std::cout << fmt::format("wrote {} fixtures (seed {}, profile {}) to {}\n", options.count,
                           options.seed, toString(options.profile), out.string());
  return kExitPass;
}

}  // namespace rc
