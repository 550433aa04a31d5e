// Backend SPECs (DESIGN.md): parsing `ref`, `ref:painter`, `ref:abuffer`, `ref:subpixel=N`
// (options combine: `ref:abuffer:subpixel=4`) and the
// `gl...` forms, and rendering one scene with one backend in this process. This is the
// only place where the reference and the GL backend meet.
#pragma once

#include <string>
#include <string_view>

#include "fixtures/frame.h"
#include "fixtures/resource_estimate.h"
#include "fixtures/scene.h"
#include "gl_backend/gl_backend.h"
#include "reference/reference_renderer.h"

namespace rc {

struct BackendSpec {
  enum class Kind { Reference, Gl };
  Kind kind = Kind::Reference;
  std::string text;  // the SPEC as the user wrote it, normalised
  ReferenceOptions reference;
  GlSpec gl;
};

// Throws InputError (exit 2) for an unknown SPEC, listing the valid forms.
BackendSpec parseBackendSpec(std::string_view spec);

// Which resource estimate (fixtures/resource_estimate.h) a backend's renders follow.
inline RendererKind rendererKind(const BackendSpec& backend) {
  return backend.kind == BackendSpec::Kind::Reference ? RendererKind::Reference : RendererKind::Gl;
}

// Renders and fills the frame.json keys every backend shares (backend, fixture, sizes,
// formats, tool version, total time). Throws BackendError (exit 3) when the backend fails.
// Without `pass_frames`, frame.passes (render --all-passes) stays empty.
Frame renderWith(const BackendSpec& backend, const Scene& scene, bool pass_frames = true);

}  // namespace rc
