// `rastercheck render SCENE --backend SPEC --out DIR`: one fixture, one backend, one
// frame directory (written all-or-nothing). A SPEC with another Mesa's folder restarts
// the process once with that folder first in LD_LIBRARY_PATH.
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/commands.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/resource_estimate.h"

namespace rc {

namespace {

// A GL SPEC naming another Mesa's folder needs LD_LIBRARY_PATH from the process's start
// (the dynamic loader reads it once): set it and run this same command again, before
// anything GL is loaded. startupEnvironment() returns the variables unchanged once they
// are in place, so this happens at most once.
void restartWithStartupEnvironment(const RenderArgs& args, const BackendSpec& backend) {
  if (backend.kind != BackendSpec::Kind::Gl) return;
  bool missing = false;
  for (const auto& [name, value] : startupEnvironment(backend.gl)) {
    const char* have = std::getenv(name.c_str());
    if (have != nullptr && value == have) continue;
    setenv(name.c_str(), value.c_str(), 1);
    missing = true;
  }
  if (!missing) return;
  const std::string exe = "/proc/self/exe";
  std::vector<std::string> argv = {exe,          "render", args.scene.string(), "--backend",
                                   args.backend, "--out",  args.out.string()};
  if (args.all_passes) argv.emplace_back("--all-passes");
  std::vector<char*> raw;
  raw.reserve(argv.size() + 1);
  for (std::string& a : argv) raw.push_back(a.data());
  raw.push_back(nullptr);
  std::cout.flush();
  ::execv(exe.c_str(), raw.data());
  throw BackendError(fmt::format("{}: cannot restart rastercheck with LD_LIBRARY_PATH: {}",
                                 args.backend, std::strerror(errno)));
}

}  // namespace

int renderCommand(const RenderArgs& args) {
  // Parse the SPEC before loading so that a typo costs nothing and exits 2.
  const BackendSpec backend = parseBackendSpec(args.backend);
  restartWithStartupEnvironment(args, backend);
  const Scene scene = loadScene(args.scene);
  checkResources(scene, rendererKind(backend), ResourceLimits::current());
  const Frame frame = renderWith(backend, scene, args.all_passes);
  writeFrameDir(frame, args.out);
  std::cout << fmt::format("{}: {} -> {}\n", scene.name, backend.text, args.out.string());
  if (args.all_passes) {
    for (const Frame& pass : frame.passes) {
      const nlohmann::json& p = pass.meta.at("pass");
      std::string name = p.at("target").get<std::string>();
      for (char& c : name)  // a folder name whatever the target is called
        if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '-' && c != '_') c = '_';
      const std::filesystem::path dir =
          args.out / "passes" / fmt::format("{}-{}", p.at("index").get<int>(), name);
      writeFrameDir(pass, dir);
      std::cout << fmt::format("  pass {} ({} {}x{}) -> {}\n", p.at("index").get<int>(),
                               p.at("target").get<std::string>(), pass.width, pass.height,
                               dir.string());
    }
  }
  return kExitPass;
}

}  // namespace rc
