// Test-only fault injection for the GL backend: lets tests prove that shader logs, GL
// errors and driver mismatches surface as BackendError. Not thread-safe; production
// code never sets these.
#pragma once

#include <string>

namespace rc::gl::testing {

struct Hooks {
  std::string vertex_shader;           // non-empty: compiled instead of the real vertex shader
  std::string fragment_shader;         // non-empty: compiled instead of the real fragment shader
  bool gl_error_after_upload = false;  // issue an invalid GL call after the upload stage
  std::string gallium_driver;          // non-empty: GALLIUM_DRIVER is set to this, not the spec's
};

// The process-wide hooks (all off by default).
Hooks& hooks();

}  // namespace rc::gl::testing
