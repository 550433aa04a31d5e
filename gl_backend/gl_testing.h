// Test-only fault injection for the GL backend. Two ways in:
//  - in-process tests set hooks() (shader replacements, a GL error, a forced driver,
//    faults);
//  - a child `rastercheck render` reads the environment variable RASTERCHECK_GL_FAULT,
//    a comma-separated list of faults (docs/gl_backend.md "Fault injection"), so the
//    harness's self-tests can prove that an injected GL-side fault is caught.
// A faulted render records "fault_injected" in frame.json and warns once on stderr.
// Not thread-safe; production code never sets these.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace rc::gl::testing {

// The environment variable read by every renderGl call (when hooks().faults is empty).
inline constexpr const char* kFaultVariable = "RASTERCHECK_GL_FAULT";

struct Faults {
  std::uint32_t drop_primitive = 0;   // drop_primitive=ID: that triangle is not drawn (0: none)
  int depth_bias_steps = 0;           // depth_bias=STEPS: stored depth + STEPS format steps
  double light_scale = 1.0;           // light_scale=F: every light's intensity times F
  bool no_inverse_transpose = false;  // normals by the model matrix, not its inverse transpose
  double shift_x_px = 0.0;            // shift_x=PX: geometry moved PX pixels right (window)
  bool shader_compile_error = false;  // shader_compile_error: the fragment shader breaks
  // move_vertex=ID: the first vertex of triangle ID alone is moved one pixel right in
  // window space (the rest of the scene is untouched): a geometry error of one vertex.
  std::uint32_t move_vertex = 0;
  // move_line_end=ID: the second vertex of segment ID (a line primitive) moved one pixel in
  // the segment's minor window direction (y for an x-major segment); move_point=ID: point
  // ID moved one pixel right. Geometry errors of lines and points.
  std::uint32_t move_line_end = 0;
  std::uint32_t move_point = 0;
  // texel_offset=N: every texture is sampled N texels to the right of the texel the
  // coordinate names (the neighbouring texel for N = 1): an addressing error.
  double texel_offset = 0.0;
  // blend_factor=one|swapped: alpha blending with the wrong factors, src*1 + dst*(1-a)
  // or src*(1-a) + dst*a, instead of src*a + dst*(1-a).
  enum class Blend { Correct, One, Swapped };
  Blend blend_factor = Blend::Correct;
  // The fragment operations' classic table errors (the fault is the value's name):
  // depth_func=inverted: LESS and GREATER, LEQUAL and GEQUAL, EQUAL and NOTEQUAL, NEVER and
  //   ALWAYS swapped in every pass that sets a depth function;
  // stencil_op=shifted: every stencil op replaced by the next in GL's list (KEEP -> ZERO ->
  //   REPLACE -> INCR -> INCR_WRAP -> DECR -> DECR_WRAP -> INVERT -> KEEP);
  // blend_function=shifted: the colour source factor of every blend function (the object
  //   form of blend) replaced by the next in the list of kBlendFactors (the last wraps);
  // scissor_shift=N: every scissor box N pixels to the right.
  bool depth_func_inverted = false;
  bool stencil_op_shifted = false;
  bool blend_function_shifted = false;
  int scissor_shift = 0;
  // lod_shift=N: every mipmapped texture's level of detail N higher (GL_TEXTURE_LOD_BIAS
  // + N): a level of detail off by N levels.
  double lod_shift = 0.0;
  // lod_weight=inverted: where a lookup blends two mip levels with weight f on the coarser,
  // it uses 1 - f (textureQueryLOD, then two textureLod): the levels right, their weights
  // wrong.
  bool lod_weight_inverted = false;
  // Shadow lookups (materials' shadow): shadow_shift=N: every lookup N map texels to the
  // right (the map offset by N texels); shadow_compare=inverted: the comparison inverted
  // as depth_func=inverted does (LEQUAL -> GEQUAL ...); shadow_bias=dropped: the bias
  // left out of the reference value.
  double shadow_shift = 0.0;
  bool shadow_compare_inverted = false;
  bool shadow_bias_dropped = false;
  // hang=NAME / crash=NAME: the render of the fixture named NAME ("*": every fixture) never
  // returns (blocks after the draw, as a driver stuck in a fence would) or dies with
  // SIGSEGV there, for the watchdog and crash tests of `run`'s workers.
  std::string hang;
  std::string crash;
  // flaky=NAME: the frame of that fixture ("*": every fixture) differs on every render (a
  // random pixel away from edges loses its primitive id, and its red is off by 64..191
  // 8-bit units: a race, an uninitialised read);
  // hang_once=NAME: its render hangs the first time in this temporary folder (a marker file
  // in TMPDIR, so the first render of any process), and renders normally afterwards.
  // For `run --retries`' flake tests.
  std::string flaky;
  std::string hang_once;

  bool any() const;
  // Whether hang / crash apply to the fixture named `fixture`.
  bool hangs(const std::string& fixture) const;
  bool crashes(const std::string& fixture) const;
  bool flakes(const std::string& fixture) const;
  bool hangsOnce(const std::string& fixture) const;
  // The canonical comma-separated form (parseFaults(describe()) gives the same faults).
  std::string describe() const;
};

// Parses "drop_primitive=3,light_scale=2". Throws InputError naming the variable and the
// offending entry for an unknown fault name or a bad value.
Faults parseFaults(std::string_view text);

struct Hooks {
  std::string vertex_shader;           // non-empty: compiled instead of the real vertex shader
  std::string fragment_shader;         // non-empty: compiled instead of the real fragment shader
  bool gl_error_after_upload = false;  // issue an invalid GL call after the upload stage
  std::string gallium_driver;          // non-empty: GALLIUM_DRIVER is set to this, not the spec's
  Faults faults;                       // any(): used instead of RASTERCHECK_GL_FAULT
  bool ignore_pack_invert = false;     // read back as if GL_MESA_pack_invert were missing
  bool program_from_source = false;    // draw with the program as linked, not its binary
  bool no_fallback_flush = false;      // a reused softpipe context skips FallbackFlush's flushes
  bool no_facing_reset = false;        // ... and resetSetupFacing's triangle
};

// The process-wide hooks (all off by default).
Hooks& hooks();

}  // namespace rc::gl::testing
