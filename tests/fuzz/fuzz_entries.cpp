// See fuzz_entries.h.
#include "tests/fuzz/fuzz_entries.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <string_view>

#include "fixtures/errors.h"
#include "fixtures/json_reader.h"
#include "fixtures/loader.h"
#include "fixtures/mesh_import.h"
#include "fixtures/message_text.h"
#include "fixtures/resource_estimate.h"
#include "fixtures/shared_cache.h"
#include "fixtures/texture_io.h"

namespace rc::fuzz {
namespace fs = std::filesystem;
namespace {

// A folder of this process's own for the files the fuzzers write.
const fs::path& scratch() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("rc-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// Every texture decoded for real, every time: the user cache (fixtures/shared_cache.h) would
// serve the images of tests/fixtures/data after their first decode, and the decoder's
// coverage with them. Set before any entry runs, in the fuzzers and their regression test.
const bool kUserCacheOff = ::setenv(kUserCacheDisableEnv, "1", 1) == 0;

}  // namespace

// The promise every refusal keeps (fixtures/errors.h): the line the command prints is
// one line of valid UTF-8 and not unbounded. Aborts with the message otherwise.
void checkRefusalMessage(const char* what) {
  const std::string line = oneLineMessage(what);
  bool ok = line.size() <= 1100 && line.find('\n') == std::string::npos &&
            line.find('\r') == std::string::npos && line.find('\0') == std::string::npos;
  // Valid UTF-8: printable() of a valid line changes only quotes and backslashes, never
  // adds \x escapes for bytes.
  ok = ok && printable(line, std::string::npos) == line;
  if (!ok) {
    std::fprintf(stderr, "message is not one safe line: %s\n", line.c_str());
    std::abort();
  }
}

std::string scratchFile(const std::string& name) { return (scratch() / name).string(); }

void loadFixtureBytes(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const fs::path source = fs::path(RC_SOURCE_DIR) / "tests/fixtures/data/fuzz.json";
  try {
    const Scene scene = loadScene(parseJsonStrict(text, source.string()), source);
    (void)estimateResources(scene, RendererKind::Reference);
    (void)estimateResources(scene, RendererKind::Gl);
  } catch (const InputError& e) {
    checkRefusalMessage(e.what());
  }
}

void importMeshBytes(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  constexpr std::size_t kFormats = std::size(kMeshExtensions);
  const fs::path file = scratchFile(std::string("mesh.") + kMeshExtensions[data[0] % kFormats]);
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    TextureCache textures;
    (void)importMeshFile(file, &textures);
  } catch (const InputError& e) {
    checkRefusalMessage(e.what());
  }
}

void decodeTextureBytes(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  constexpr std::size_t kFormats = std::size(kTextureExtensions);
  const auto* bytes = reinterpret_cast<const std::byte*>(data + 1);
  try {
    (void)decodeTexture(std::span<const std::byte>(bytes, size - 1),
                        kTextureExtensions[data[0] % kFormats], "fuzz");
  } catch (const InputError& e) {
    checkRefusalMessage(e.what());
  }
}

}  // namespace rc::fuzz
