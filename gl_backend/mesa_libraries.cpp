// Mesa library folders, the driver environment and the loaded-library check: see
// mesa_libraries.h and docs/gl_backend.md ("Drivers from a Mesa build").
#include "gl_backend/mesa_libraries.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <set>

#include <fmt/format.h>

#include "fixtures/errors.h"

#ifndef RC_OSMESA_SONAME
#define RC_OSMESA_SONAME "libOSMesa.so.8"
#endif

namespace rc::gl {
namespace fs = std::filesystem;
namespace {

bool startsWith(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

bool endsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// The canonical folder of spec.mesa_dir (it exists: checkMesaDir ran at parse time).
fs::path mesaDir(const GlSpec& spec) {
  std::error_code ec;
  fs::path dir = fs::canonical(spec.mesa_dir, ec);
  if (ec) throw BackendError(fmt::format("Mesa folder {}: {}", spec.mesa_dir, ec.message()));
  return dir;
}

bool isFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);  // follows symlinks, as dlopen does
}

// Writes `text` to `file` unless it already holds exactly that (several processes may
// write the same file at once: each writes its own temporary and renames it).
void writeIfChanged(const fs::path& file, const std::string& text) {
  {
    std::ifstream in(file, std::ios::binary);
    if (in) {
      const std::string have((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
      if (have == text) return;
    }
  }
  const fs::path tmp = file.string() + fmt::format(".{}.tmp", ::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush())
      throw BackendError(fmt::format("cannot write {}: {}", tmp.string(), std::strerror(errno)));
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw BackendError(fmt::format("cannot write {}: {}", file.string(), ec.message()));
  }
}

// A small JSON file (glvnd vendor or Vulkan ICD manifest) in the private runtime folder,
// named after what it points to so that every process asking for the same folder shares
// one file.
fs::path manifest(const std::string& kind, const fs::path& library, const nlohmann::json& doc) {
  fs::path file = privateRuntimeDir() /
                  fmt::format("{}-{:016x}.json", kind, std::hash<std::string>{}(library.string()));
  writeIfChanged(file, doc.dump(2) + "\n");
  return file;
}

bool isMesaLibrary(std::string_view name) {
  for (const char* prefix : {"libEGL_mesa.so", "libGLX_mesa.so", "libglapi.so", "libgbm.so",
                             "libOSMesa.so", "libgallium", "libvulkan_"}) {
    if (startsWith(name, prefix)) return true;
  }
  return endsWith(name, "_dri.so");
}

bool holdsDriver(std::string_view name) {
  return endsWith(name, "_dri.so") || startsWith(name, "libgallium") ||
         startsWith(name, "libOSMesa.so");
}

bool inside(const std::string& path, const std::string& dir) { return startsWith(path, dir + "/"); }

// Whether the LD_LIBRARY_PATH value `have` (null: unset) starts with `dir` (what
// startupEnvironment asks for).
bool startupEnvironmentApplied(const std::string& dir, const char* have) {
  if (have == nullptr) return false;
  const std::string_view list(have);
  return list.substr(0, list.find(':')) == dir;
}

}  // namespace

void checkMesaDir(std::string_view spec_text, const GlSpec& spec) {
  if (spec.mesa_dir.empty()) return;
  const fs::path dir(spec.mesa_dir);
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st))
    throw InputError(
        fmt::format("backend '{}': Mesa folder {} does not exist", spec_text, spec.mesa_dir));
  if (!fs::is_directory(st))
    throw InputError(
        fmt::format("backend '{}': Mesa folder {} is not a folder", spec_text, spec.mesa_dir));
  const char* hint = "name the library folder of a Mesa install, e.g. PREFIX/lib/x86_64-linux-gnu";
  if (spec.platform == GlSpec::Platform::OSMesa) {
    if (!isFile(dir / RC_OSMESA_SONAME))
      throw InputError(fmt::format("backend '{}': {} holds no {} ({})", spec_text, spec.mesa_dir,
                                   RC_OSMESA_SONAME, hint));
    return;
  }
  if (!isFile(dir / kEglVendorLibrary) && !isFile(dir / kEglLibrary))
    throw InputError(fmt::format("backend '{}': {} holds neither {} nor {} ({})", spec_text,
                                 spec.mesa_dir, kEglVendorLibrary, kEglLibrary, hint));
  if (spec.driver == "zink" && !isFile(dir / kLavapipeLibrary))
    throw InputError(fmt::format(
        "backend '{}': {} holds no {} (zink runs on that Mesa's lavapipe; build Mesa with "
        "-Dvulkan-drivers=swrast)",
        spec_text, spec.mesa_dir, kLavapipeLibrary));
}

fs::path privateRuntimeDir() {
  const char* tmp = std::getenv("TMPDIR");
  const fs::path base = tmp != nullptr && *tmp == '/' ? fs::path(tmp) : fs::path("/tmp");
  fs::path dir = base / fmt::format("rastercheck-{}", ::getuid());
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST)
    throw BackendError(fmt::format("cannot create {}: {}", dir.string(), std::strerror(errno)));
  // Someone else's folder (or a symlink planted in a shared /tmp) must not be used.
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::getuid() ||
      (st.st_mode & 077) != 0) {
    throw BackendError(
        fmt::format("{} is not a private folder of this user (mode 0700, not a symlink); remove it",
                    dir.string()));
  }
  return dir;
}

void prepareDriverEnvironment(const GlSpec& spec, const std::string& gallium) {
  if (!gallium.empty()) {
    // Read by Mesa when the first screen is created; later changes have no effect.
    setenv("GALLIUM_DRIVER", gallium.c_str(), 1);
    // Surfaceless EGL would prefer a GPU render node; a software driver was asked for.
    // zink needs it too: it then picks a CPU Vulkan device (lavapipe), and without it
    // Mesa's EGL does not offer zink at all (MESA_LOADER_DRIVER_OVERRIDE alone fails).
    if (spec.platform == GlSpec::Platform::EglSurfaceless) setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
  }
  const char* gallium_env = std::getenv("GALLIUM_DRIVER");
  const bool zink = gallium == "zink" || (gallium.empty() && gallium_env != nullptr &&
                                          std::string_view(gallium_env) == "zink");
  if (zink) {
    const char* runtime = std::getenv("XDG_RUNTIME_DIR");
    std::error_code ec;
    if (runtime == nullptr || *runtime != '/' || !fs::is_directory(runtime, ec))
      setenv("XDG_RUNTIME_DIR", privateRuntimeDir().c_str(), 1);
  }
  if (spec.mesa_dir.empty()) return;
  const fs::path dir = mesaDir(spec);
  // Mesa's loader reads LIBGL_DRIVERS_PATH for EGL's DRI drivers (not when setuid).
  if (std::error_code ec; fs::is_directory(dir / "dri", ec))
    setenv("LIBGL_DRIVERS_PATH", (dir / "dri").c_str(), 1);
  if (spec.platform != GlSpec::Platform::OSMesa && isFile(dir / kEglVendorLibrary)) {
    // glvnd's libEGL reads its vendor list on the first EGL call: only this Mesa's.
    const fs::path vendor = dir / kEglVendorLibrary;
    const nlohmann::json doc = {{"file_format_version", "1.0.0"},
                                {"ICD", {{"library_path", vendor.string()}}}};
    setenv("__EGL_VENDOR_LIBRARY_FILENAMES", manifest("egl-vendor", vendor, doc).c_str(), 1);
  }
  if (zink) {
    const fs::path lavapipe = dir / kLavapipeLibrary;
    const nlohmann::json doc = {
        {"file_format_version", "1.0.0"},
        {"ICD", {{"library_path", lavapipe.string()}, {"api_version", "1.3.0"}}}};
    const fs::path icd = manifest("vk-icd", lavapipe, doc);
    setenv("VK_DRIVER_FILES", icd.c_str(), 1);   // Vulkan loader 1.3.207 and later
    setenv("VK_ICD_FILENAMES", icd.c_str(), 1);  // older loaders
  }
}

LoadedMesa checkLoadedMesa(const GlSpec& spec) {
  LoadedMesa out;
  if (!spec.mesa_dir.empty()) out.dir = mesaDir(spec).string();
  std::ifstream maps("/proc/self/maps");
  std::set<std::string> seen;
  for (std::string line; std::getline(maps, line);) {
    // address perms offset dev inode pathname
    const std::size_t slash = line.find('/');
    if (slash == std::string::npos) continue;
    std::string path = line.substr(slash);
    if (endsWith(path, " (deleted)")) path.resize(path.size() - 10);
    const std::string name = fs::path(path).filename().string();
    const bool from_dir = !out.dir.empty() && inside(path, out.dir);
    if (!isMesaLibrary(name) &&
        !(from_dir && startsWith(name, "lib") && name.find(".so") != std::string::npos))
      continue;
    if (seen.insert(path).second) out.libraries.push_back(path);
  }
  std::sort(out.libraries.begin(), out.libraries.end());
  for (const std::string& lib : out.libraries) {
    if (holdsDriver(fs::path(lib).filename().string())) {
      out.driver_library = lib;
      break;
    }
  }
  if (out.dir.empty()) return out;
  bool any_inside = false;
  for (const std::string& lib : out.libraries) {
    if (inside(lib, out.dir)) {
      any_inside = true;
    } else {
      throw BackendError(fmt::format(
          "asked for the Mesa in {}, but this process loaded {} from outside it{}", out.dir, lib,
          startupEnvironmentApplied(out.dir, std::getenv("LD_LIBRARY_PATH"))
              ? ""
              : " (LD_LIBRARY_PATH does not start with it: render through `rastercheck "
                "render`, which sets it)"));
    }
  }
  if (!any_inside)
    throw BackendError(
        fmt::format("asked for the Mesa in {}, but no library from it was loaded", out.dir));
  return out;
}

std::string mesaVersion(const std::string& gl_version) {
  const std::size_t at = gl_version.find("Mesa ");
  return at == std::string::npos ? std::string() : gl_version.substr(at);
}

nlohmann::json toJson(const LoadedMesa& mesa, const GlSpec& spec, const std::string& version) {
  return {
      {"version", version.empty() ? nlohmann::json(nullptr) : nlohmann::json(version)},
      {"asked", spec.mesa_dir.empty() ? nlohmann::json(nullptr) : nlohmann::json(spec.mesa_dir)},
      {"dir", mesa.dir.empty() ? nlohmann::json(nullptr) : nlohmann::json(mesa.dir)},
      {"driver_library",
       mesa.driver_library.empty() ? nlohmann::json(nullptr) : nlohmann::json(mesa.driver_library)},
      {"libraries", mesa.libraries}};
}

}  // namespace rc::gl

namespace rc {

std::vector<std::pair<std::string, std::string>> startupEnvironment(const GlSpec& spec) {
  return startupEnvironment(spec, std::getenv("LD_LIBRARY_PATH"));
}

std::vector<std::pair<std::string, std::string>> startupEnvironment(const GlSpec& spec,
                                                                    const char* old) {
  if (spec.mesa_dir.empty()) return {};
  const std::string dir = gl::mesaDir(spec).string();
  // Already first: the process was started with it (idempotent, so no exec loop).
  if (gl::startupEnvironmentApplied(dir, old)) return {{"LD_LIBRARY_PATH", old}};
  std::string value = dir;
  if (old != nullptr && *old != '\0') {
    value += ':';
    value += old;
  }
  return {{"LD_LIBRARY_PATH", value}};
}

}  // namespace rc
