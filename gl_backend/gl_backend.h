// The offscreen OpenGL backend: renders a Scene with real GL (Mesa llvmpipe/softpipe
// through EGL or OSMesa, or a GPU through an EGL device) into an FBO and reads it back
// as a Frame, following the same semantics as the reference (../shared/DESIGN.md).
// It does not produce the reference's uncertainty channels (edge_dist, depth_gap).
#pragma once

#include <string>
#include <string_view>

#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc {

struct GlSpec {
  enum class Platform { EglSurfaceless, EglDevice, OSMesa };
  Platform platform = Platform::EglSurfaceless;
  std::string driver;  // "", llvmpipe, softpipe ("" = the platform's default)
  int device = -1;     // egl-device index, -1 = first hardware device
};

// "gl", "gl:egl", "gl:egl:llvmpipe", "gl:egl:softpipe", "gl:osmesa",
// "gl:osmesa:llvmpipe", "gl:osmesa:softpipe", "gl:egl-device", "gl:egl-device:N".
// Anything else throws InputError naming the spec and listing the valid forms.
GlSpec parseGlSpec(std::string_view spec);

// The canonical spelling; parseGlSpec(toString(s)) gives s back.
std::string toString(const GlSpec& spec);

// Renders one scene. The first call in a process picks the driver (GALLIUM_DRIVER is
// read once per process); later calls reuse that context. Throws BackendError with one
// line "<fixture name>: <backend spec>: <why>" when GL cannot start or reports an error,
// and InputError for a scene no renderer could draw (non-positive size, bad indices).
Frame renderGl(const Scene& scene, const GlSpec& spec);

}  // namespace rc
