// `rastercheck generate --seed S --count N --out DIR`: reproducible random fixtures
// (fixtures/random_scene.h), the folder replaced all-or-nothing (fixtures/output_folder.h).
#include <charconv>
#include <iostream>
#include <limits>
#include <regex>

#include <fmt/format.h>

#include "app/commands.h"
#include "fixtures/errors.h"
#include "fixtures/output_folder.h"
#include "fixtures/random_scene.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

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

RandomSceneOptions generateOptions(const GenerateArgs& args) {
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
  return options;
}

int generateCommand(const GenerateArgs& args) {
  const RandomSceneOptions options = generateOptions(args);

  // "DIR/" and "DIR/." name DIR itself.
  fs::path out = fs::absolute(args.out).lexically_normal();
  if (!out.has_filename()) out = out.parent_path();
  if (out == out.root_path()) throw InputError("--out: cannot be the root folder");
  // The folder is replaced whole (fixtures/output_folder.h), so it must be one that
  // `generate` wrote, or new, or empty.
  std::error_code ec;
  if (fs::is_directory(out, ec) && !fs::is_empty(out, ec) && !fs::exists(out / kRandomManifest, ec))
    throw InputError(fmt::format(
        "{}: --out is a folder that `generate` did not write (no {}); name a new or empty "
        "folder",
        out.string(), kRandomManifest));
  OutputFolder folder(out, {"*"});
  writeRandomFixtures(options, folder.staging());
  folder.commit();
  std::cout << fmt::format("wrote {} fixtures (seed {}, profile {}) to {}\n", options.count,
                           options.seed, toString(options.profile), out.string());
  return kExitPass;
}

}  // namespace rc
