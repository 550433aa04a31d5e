// Which Mesa a GL backend runs on: the "@DIR" folder of another Mesa (checked before
// anything loads), the environment every driver stack needs before its first context
// (Gallium driver, software rendering, a private XDG_RUNTIME_DIR for zink's Vulkan
// loader, glvnd's vendor file and the DRI and Vulkan driver paths of a Mesa folder), and
// afterwards the Mesa libraries this process really mapped (from /proc/self/maps), so
// that a render never silently runs on another Mesa than the one asked for.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gl_backend/gl_backend.h"

namespace rc::gl {

// The file names rastercheck looks for in a Mesa library folder.
inline constexpr const char* kEglVendorLibrary = "libEGL_mesa.so.0";  // glvnd's Mesa vendor
inline constexpr const char* kEglLibrary = "libEGL.so.1";             // a Mesa built without glvnd
inline constexpr const char* kLavapipeLibrary = "libvulkan_lvp.so";   // zink's Vulkan driver

// Throws InputError (one line naming the spec and the folder) when spec.mesa_dir is set
// and does not exist, is not a folder, or lacks what the platform loads: libEGL_mesa.so.0
// or libEGL.so.1 for EGL, the OSMesa library for OSMesa, and libvulkan_lvp.so for zink.
void checkMesaDir(std::string_view spec_text, const GlSpec& spec);

// Sets, before the process's first context, the environment the spec's driver stack
// reads when it loads: GALLIUM_DRIVER (`gallium`, when not empty) and, on EGL,
// LIBGL_ALWAYS_SOFTWARE=1; for zink a private XDG_RUNTIME_DIR when none is set (the
// Vulkan loader's window-system code complains on every start without one); for a Mesa
// folder LIBGL_DRIVERS_PATH=DIR/dri, __EGL_VENDOR_LIBRARY_FILENAMES naming DIR's
// libEGL_mesa.so.0 (so glvnd loads no other vendor) and, for zink, VK_DRIVER_FILES naming
// DIR's lavapipe. Throws BackendError when a file it needs cannot be written.
void prepareDriverEnvironment(const GlSpec& spec, const std::string& gallium);

// A folder only this user can use, for XDG_RUNTIME_DIR and the generated vendor files:
// $TMPDIR/rastercheck-<uid> (mode 0700, owned by this user, not a symlink), created when
// missing. Throws BackendError when no such folder can be had.
std::filesystem::path privateRuntimeDir();

// The Mesa libraries mapped into this process right now (libEGL_mesa, libglapi, libgbm,
// *_dri.so, libgallium*, libOSMesa, libvulkan_<driver>, and libEGL/libGL when they come
// from the asked folder), as real paths, sorted.
struct LoadedMesa {
  std::string dir;                     // the asked folder's real path; "" = the system's Mesa
  std::vector<std::string> libraries;  // real paths
  std::string driver_library;          // the one that holds the driver (*_dri.so, libgallium,
                                       // libOSMesa), "" when none is mapped
};

// Reads /proc/self/maps. With a Mesa folder, throws BackendError (one line) when a Mesa
// library was loaded from outside it or none from it: what was asked is not what runs.
LoadedMesa checkLoadedMesa(const GlSpec& spec);

// "Mesa 22.3.6" from a GL_VERSION such as "4.5 (Core Profile) Mesa 22.3.6"; "" when the
// version string names no Mesa.
std::string mesaVersion(const std::string& gl_version);

// frame.json "mesa": {"version", "dir", "asked", "driver_library", "libraries"}.
nlohmann::json toJson(const LoadedMesa& mesa, const GlSpec& spec, const std::string& version);

}  // namespace rc::gl
