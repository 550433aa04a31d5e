// The offscreen OpenGL backend: renders a Scene with real GL (Mesa llvmpipe/softpipe
// through EGL or OSMesa, zink over lavapipe through EGL, or a GPU through an EGL device),
// from the system's Mesa or from another Mesa's library folder, into an FBO and reads it back
// as a Frame, following the same semantics as the reference (../shared/DESIGN.md).
// It does not produce the reference's uncertainty channels (edge_dist, depth_gap).
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc {

struct GlSpec {
  enum class Platform { EglSurfaceless, EglDevice, OSMesa };
  Platform platform = Platform::EglSurfaceless;
  std::string driver;  // "", llvmpipe, softpipe, zink (EGL only) ("" = the platform's default)
  int device = -1;     // egl-device index, -1 = first hardware device
  // "@DIR": the library folder of another Mesa (as written; "" = the system's Mesa).
  std::string mesa_dir;
};

// "gl", "gl:egl", "gl:egl:llvmpipe", "gl:egl:softpipe", "gl:egl:zink", "gl:osmesa",
// "gl:osmesa:llvmpipe", "gl:osmesa:softpipe", "gl:egl-device", "gl:egl-device:N", each
// optionally followed by "@DIR" (DIR: a Mesa install's library folder, docs/gl_backend.md).
// Anything else throws InputError naming the spec and listing the valid forms; so does a
// DIR that does not exist or holds no library the platform needs (checkMesaDir).
GlSpec parseGlSpec(std::string_view spec);

// The same grammar without looking at the file system (no Mesa folder check).
GlSpec parseGlSpecSyntax(std::string_view spec);

// The canonical spelling; parseGlSpec(toString(s)) gives s back.
std::string toString(const GlSpec& spec);

// Environment variables the dynamic loader reads only when a process starts
// (LD_LIBRARY_PATH=DIR for a spec with a Mesa folder, so that every library of that Mesa
// and what it links comes from DIR); empty for the system's Mesa. `rastercheck render`
// re-executes itself with them before loading any driver; a render in a process started
// without them fails the loaded-library check (exit 3) unless glvnd's vendor file and
// LIBGL_DRIVERS_PATH, which renderGl sets itself, are enough.
std::vector<std::pair<std::string, std::string>> startupEnvironment(const GlSpec& spec);
// The same for a given LD_LIBRARY_PATH value (null: unset), without reading the process
// environment (tests: setenv in a process whose GL driver runs threads is a data race).
std::vector<std::pair<std::string, std::string>> startupEnvironment(const GlSpec& spec,
                                                                    const char* ld_library_path);

// Renders one scene. The first call in a process picks the driver (GALLIUM_DRIVER is
// read once per process); later calls reuse that context. Throws BackendError with one
// line "<fixture name>: <backend spec>: <why>" when GL cannot start or reports an error,
// and InputError for a scene no renderer could draw (non-positive size, bad indices).
// The frame's `drawn` facts come from the scene, as the reference's do. A multi-pass
// scene's pass frames (frame.passes) are read back only with `pass_frames`.
Frame renderGl(const Scene& scene, const GlSpec& spec, bool pass_frames = true);

}  // namespace rc
