// renderGl: the process-wide GL session, the FBO, the draw sequence of drawPasses() and
// the readback into a Frame (top row first). See gl_backend.h and docs/gl_backend.md.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include "fixtures/errors.h"
#include "fixtures/mipmaps.h"
#include "fixtures/multisample.h"
#include "fixtures/scene_logic.h"
#include "gl_backend/context.h"
#include "gl_backend/gl_backend.h"
#include "gl_backend/gl_functions.h"
#include "gl_backend/gl_testing.h"
#include "gl_backend/mesa_libraries.h"
#include "gl_backend/shaders.h"
#include "gl_backend/vertex_data.h"
#include "gl_backend/vulkan_device.h"

namespace rc {

namespace gl::testing {
Hooks& hooks() {
  static Hooks instance;
  return instance;
}
}  // namespace gl::testing

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of the calling thread: the harness's own stages (upload, readback) run on it,
// and unlike wall time it does not grow when other processes share the cores.
double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

const char* glErrorName(GLenum error) {
  switch (error) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    default:
      return "unknown GL error";
  }
}

const char* framebufferStatusName(GLenum status) {
  switch (status) {
    case GL_FRAMEBUFFER_UNDEFINED:
      return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER:
      return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER:
      return "GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED:
      return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE:
      return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    default:
      return "unknown framebuffer status";
  }
}

std::string glString(const gl::Functions& gl, GLenum name) {
  const auto* s = reinterpret_cast<const char*>(gl.GetString(name));
  return s != nullptr ? s : "";
}

int glInteger(const gl::Functions& gl, GLenum name) {
  GLint value = 0;
  gl.GetIntegerv(name, &value);
  return value;
}

// "llvmpipe (LLVM 15.0.6, 256 bits)" -> "llvmpipe", "zink (llvmpipe (...))" -> "zink"; a
// GPU keeps its full renderer string.
std::string driverFromRenderer(const std::string& renderer) {
  if (renderer.rfind("zink", 0) == 0) return "zink";  // before llvmpipe: zink names its device
  if (renderer.find("llvmpipe") != std::string::npos) return "llvmpipe";
  if (renderer.find("softpipe") != std::string::npos) return "softpipe";
  return renderer;
}

// Uniform locations of the one program, looked up once per program.
struct Program {
  GLuint id = 0;
  bool from_binary = false;  // made from its glGetProgramBinary bytes (throughBinary)
  int max_lights = 0;
  GLint view_projection = -1, shading = -1, eye = -1, ambient_light = -1, light_count = -1;
  GLint light_type = -1, light_position = -1, light_direction = -1, light_color = -1;
  GLint light_intensity = -1, specular_model = -1, attenuation = -1;
  GLint material_ambient = -1, material_diffuse = -1, material_specular = -1, shininess = -1;
  GLint opacity = -1, has_texture = -1, texture = -1;
  GLint fault_depth_bias = -1, fault_shift_ndc = -1, fault_texel_offset = -1, fault_lod_bias = -1,
        fault_shadow_shift = -1;  // -1 unless compiled with the fault
  // Shadow lookups (-1 in programs without them).
  GLint shadow_map = -1, shadow_matrix = -1, shadow_bias = -1, light_shadowed = -1;
};

// The FBO of the last render, kept for the next one of the same size and formats:
// allocating 1080p attachments costs more than the rest of the upload.
struct Framebuffer {
  GLuint framebuffer = 0;
  GLuint renderbuffers[4] = {0, 0, 0, 0};  // colour, ids, depth (and stencil), d16's stencil
  int width = 0;
  int height = 0;
  ColorFormat color = ColorFormat::RGBA32F;
  DepthFormat depth = DepthFormat::D24;
  StencilFormat stencil = StencilFormat::None;
};

// Readback of the formats that need converting (d16, rgba8) lands here first (warm
// memory, reused between renders); everything else goes straight into the Frame.
struct Scratch {
  std::vector<std::uint16_t> halves;
  std::vector<std::uint8_t> bytes;
};

// One GL context per process (GALLIUM_DRIVER is read once per process), reused by every
// call for a compatible spec.
struct Session {
  GlSpec spec;
  std::unique_ptr<gl::Context> context;
  gl::Functions gl;
  std::string vendor, renderer, version, glsl_version, driver;
  int gl_subpixel_bits = 0;  // GL_SUBPIXEL_BITS, as the driver answers it
  int subpixel_bits = 0;     // the precision it rasterizes with (chooseSubpixelBits)
  std::string subpixel_source;
  gl::LoadedMesa mesa;  // frame.json "mesa"
  std::string mesa_version;
  bool zink = false;                       // frame.json "vulkan" only then:
  std::optional<gl::VulkanDevice> vulkan;  // the device under zink, or
  std::string vulkan_error;                // why it could not be asked
  double vulkan_query_ms = 0.0;
  std::string stack;                        // frame.json "stack": the layers in one line
  std::map<std::string, Program> programs;  // by source text
  std::vector<std::string> debug_errors;    // KHR_debug error messages since the last check
  Framebuffer framebuffer;
  Scratch scratch;
  GLuint sample_program = 0;  // reads one sample of the ids / depth (multisampled renders)
  GLuint empty_vertex_array = 0;
  // resetSetupFacing's triangle: its program and a 1x1 framebuffer (0: not made yet).
  GLuint facing_program = 0;
  GLuint facing_framebuffer = 0;
  GLuint facing_renderbuffer = 0;
  // A render that did not finish (its context state unknown): the next gets a new context
  // even where contexts are reused (reusesContext).
  bool render_unfinished = false;
  // Mesa's fallback textures (FallbackFlush) this context has created, and those a new
  // context would have created by now in the current render.
  unsigned fallbacks_created = 0;
  unsigned fallbacks_this_render = 0;
  const char* context_use = "new";       // frame.json "context": new, reused or replaced
  const char* program_use = "compiled";  // frame.json "program": compiled or reused
  bool program_binary = false;           // frame.json "program_binary"
};

// Mesa's fallback textures, what a sampler reads where its unit holds no complete texture:
// Mesa creates one per target and kind (colour, depth) the first time a draw in a share group
// needs it, and finishes the context when it does (_mesa_get_fallback_texture,
// src/mesa/main/texobj.c; on softpipe glFinish and glFlush both flush). softpipe's flush
// writes its colour tile cache back to an rgba8 buffer, and blending after it reads the
// stored 8-bit values instead of the cache's floats (docs/results/findings.md, "softpipe: a
// reused context changed later frames"). A new context therefore flushes at the render's
// first draw with an empty unit its program samples, and a reused one, whose fallbacks exist,
// would not: before each draw in a softpipe context, beforeDraw() flushes where a new
// context's Mesa would have.
struct FallbackFlush {
  static constexpr unsigned kColor2D = 1;  // sampler2D on unit 0 (the material's texture)
  static constexpr unsigned kDepth2D = 2;  // sampler2DShadow on unit 1 (the shadow map)
  Session* s = nullptr;                    // null: the driver's frames do not depend on it
  bool shadow_unit = false;                // the program has the shadow sampler

  FallbackFlush(Session& session, const Program& program)
      : s(session.driver == "softpipe" && !gl::testing::hooks().no_fallback_flush ? &session
                                                                                  : nullptr),
        shadow_unit(program.shadow_map >= 0) {}

  void beforeDraw() const {
    if (s == nullptr) return;
    const gl::Functions& gl = s->gl;
    GLint active = GL_TEXTURE0;
    gl.GetIntegerv(GL_ACTIVE_TEXTURE, &active);
    const auto empty = [&](GLenum unit) {
      GLint texture = 0;
      gl.ActiveTexture(unit);
      gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
      return texture == 0;
    };
    unsigned needed = empty(GL_TEXTURE0) ? kColor2D : 0;
    if (shadow_unit && empty(GL_TEXTURE1)) needed |= kDepth2D;
    gl.ActiveTexture(static_cast<GLenum>(active));
    const unsigned first = needed & ~s->fallbacks_this_render;
    if (first == 0) return;
    // Where the context lacks one of them, Mesa flushes by itself.
    if ((first & ~s->fallbacks_created) == 0) gl.Flush();
    s->fallbacks_this_render |= first;
    s->fallbacks_created |= first;
  }
};

std::mutex g_mutex;
// Deliberately never destroyed: tearing EGL/OSMesa down from a static destructor races
// with the drivers' own exit handlers. The OS reclaims the context.
Session* g_session = nullptr;

void APIENTRY onDebugMessage(GLenum /*source*/, GLenum type, GLuint /*id*/, GLenum /*severity*/,
                             GLsizei length, const GLchar* message, const void* user) {
  if (type != GL_DEBUG_TYPE_ERROR) return;
  auto* session = static_cast<Session*>(const_cast<void*>(user));
  session->debug_errors.emplace_back(
      message, length >= 0 ? static_cast<std::size_t>(length) : std::strlen(message));
}

// Throws BackendError when GL reported an error since the last check.
void checkGl(Session& s, const char* stage) {
  const GLenum first = s.gl.GetError();
  for (int i = 0; i < 16 && s.gl.GetError() != GL_NO_ERROR; ++i) {
  }
  if (first == GL_NO_ERROR && s.debug_errors.empty()) return;
  const std::string detail = s.debug_errors.empty() ? "" : ": " + s.debug_errors.front();
  s.debug_errors.clear();
  throw BackendError(fmt::format("GL error {} after {}{}",
                                 first == GL_NO_ERROR ? "(debug output)" : glErrorName(first),
                                 stage, detail));
}

// zink's GL_SUBPIXEL_BITS is Gallium's default (4), not its device's: Mesa 22.3.6 answers
// 4 while lavapipe, which does the rasterizing, snaps to 8 bits (the variant probe sees
// 8). The comparator's snap band must follow what really happens, so under zink the
// Vulkan device's subPixelPrecisionBits is used; the GL answer stays in frame.json as
// gl_subpixel_bits and the variant probe reports the discrepancy.
void chooseSubpixelBits(Session& s) {
  s.subpixel_bits = s.gl_subpixel_bits;
  s.subpixel_source = "GL_SUBPIXEL_BITS";
  if (s.vulkan && s.vulkan->subpixel_precision_bits >= 0) {
    s.subpixel_bits = s.vulkan->subpixel_precision_bits;
    s.subpixel_source = "VkPhysicalDeviceLimits::subPixelPrecisionBits";
  }
}

const char* platformName(GlSpec::Platform p) {
  switch (p) {
    case GlSpec::Platform::EglSurfaceless:
      return "EGL surfaceless";
    case GlSpec::Platform::EglDevice:
      return "EGL device";
    case GlSpec::Platform::OSMesa:
      return "OSMesa";
  }
  return "";
}

// "zink (llvmpipe (...)) | OpenGL 4.6 (Core Profile) Mesa 22.3.6 | EGL surfaceless |
// Vulkan 1.3.230 llvmpipe (...) [llvmpipe, Mesa 22.3.6 (LLVM 15.0.6)] | driver
// /usr/lib/x86_64-linux-gnu/dri/swrast_dri.so", plus "(Mesa folder DIR)" for an @DIR spec.
std::string describeStack(const Session& s, const gl::LoadedMesa& mesa) {
  std::string out =
      fmt::format("{} | OpenGL {} | {}", s.renderer, s.version, platformName(s.spec.platform));
  if (s.vulkan) {
    out += fmt::format(" | Vulkan {} {}", s.vulkan->api_version, s.vulkan->name);
    if (!s.vulkan->driver_name.empty())
      out += fmt::format(" [{}, {}]", s.vulkan->driver_name, s.vulkan->driver_info);
  }
  if (!mesa.driver_library.empty()) out += " | driver " + mesa.driver_library;
  if (!mesa.dir.empty()) out += " (Mesa folder " + mesa.dir + ")";
  return out;
}

void enableDebugOutput(Session& s) {
  if (s.gl.DebugMessageCallback == nullptr) return;
  s.gl.Enable(GL_DEBUG_OUTPUT);
  s.gl.Enable(GL_DEBUG_OUTPUT_SYNCHRONOUS);  // errors arrive inside the failing call
  s.gl.DebugMessageCallback(&onDebugMessage, &s);
}

// zink in Mesa 22 frees a context's batch states when the context is destroyed, while
// resources may still point at them (the last batch that read or wrote them); a later
// context that waits on such a resource sleeps on a condition variable in freed memory: a
// hang or an abort (docs/results/findings.md, "zink on Mesa 22: a destroyed context leaves
// dangling batch usage"). With one context per process that cannot happen, so under zink
// on Mesa 22 a process keeps its context, and each render starts from the state
// resetReusedContext leaves (everything a fresh context has that a render does not set
// itself). Later zink hands a destroyed context's batch states to the screen instead.
bool keepsOneContext(const Session& s) {
  return s.zink && s.mesa_version.rfind("Mesa 22.", 0) == 0;
}

// Whether the next render reuses this process's context, and with it the programs it
// compiled, instead of starting from a new one (resetReusedContext() restores what a render
// does not set itself): where the isolation test shows that a frame is the one a new context
// gives, whatever the context drew before (GlBackend.FramesDoNotDependOnWhatWasDrawnBefore),
// that is llvmpipe, zink and softpipe (softpipe with FallbackFlush and resetSetupFacing); zink
// on Mesa 22 in any case (keepsOneContext). A driver the test has not run on (a GPU) gets a
// new context per render. RASTERCHECK_GL_CONTEXT=new gives every driver but zink on Mesa 22 a
// new context per render, =reuse reuses it on every driver and render (to test one); it is
// read at every render.
bool reusesContext(const Session& s) {
  if (keepsOneContext(s)) return true;
  const char* forced = std::getenv("RASTERCHECK_GL_CONTEXT");
  if (forced != nullptr && std::string_view(forced) == "new") return false;
  if (forced != nullptr && std::string_view(forced) == "reuse") return true;
  return s.driver == "llvmpipe" || s.driver == "zink" || s.driver == "softpipe";
}

std::unique_ptr<Session> createSession(const GlSpec& spec) {
  const std::string& forced = gl::testing::hooks().gallium_driver;
  const std::string gallium = forced.empty() ? spec.driver : forced;
  gl::prepareDriverEnvironment(spec, gallium);
  auto s = std::make_unique<Session>();
  s->spec = spec;
  switch (spec.platform) {
    case GlSpec::Platform::EglSurfaceless:
      s->context = gl::createEglSurfacelessContext();
      break;
    case GlSpec::Platform::EglDevice:
      s->context = gl::createEglDeviceContext(spec.device);
      break;
    case GlSpec::Platform::OSMesa:
      s->context = gl::createOsMesaContext(spec.mesa_dir);
      break;
  }
  s->context->makeCurrent();
  gl::Functions& gl = s->gl;
  gl.load(s->context->loader());
  s->vendor = glString(gl, GL_VENDOR);
  s->renderer = glString(gl, GL_RENDERER);
  s->version = glString(gl, GL_VERSION);
  s->glsl_version = glString(gl, GL_SHADING_LANGUAGE_VERSION);
  s->gl_subpixel_bits = glInteger(gl, GL_SUBPIXEL_BITS);
  s->driver = driverFromRenderer(s->renderer);
  const int major = glInteger(gl, GL_MAJOR_VERSION);
  const int minor = glInteger(gl, GL_MINOR_VERSION);
  if (major * 10 + minor < 33)
    throw BackendError(fmt::format("need OpenGL 3.3 core, {} gives {}", s->renderer, s->version));
  if (!spec.driver.empty() && s->driver != spec.driver) {
    throw BackendError(fmt::format("asked for {}, GL_RENDERER is {} (no silent substitution)",
                                   spec.driver, s->renderer));
  }
  // What was loaded, after the driver created its screen (and zink its Vulkan device).
  const gl::LoadedMesa loaded = gl::checkLoadedMesa(spec);
  s->mesa = loaded;
  s->mesa_version = gl::mesaVersion(s->version);
  if (s->driver == "zink") {
    s->zink = true;
    const auto start = Clock::now();  // a Vulkan instance of its own: part of the context
    s->vulkan = gl::queryVulkanDevice(gl::zinkDeviceName(s->renderer), s->vulkan_error);
    s->vulkan_query_ms = msSince(start);
  }
  chooseSubpixelBits(*s);
  s->stack = describeStack(*s, loaded);
  enableDebugOutput(*s);
  checkGl(*s, "context creation");
  return s;
}

// A new context for the next render, on the driver this process already loaded: where a
// driver's frames could depend on what the context drew before (reusesContext), every
// render starts from a fresh context's state, as it did when each render was a process of
// its own (docs/gl_backend.md).
// `abandon_old`: leave the old context allocated instead of destroying it (zink on Mesa 22
// cannot take the destruction; see acquireSession).
void renewContext(Session& s, bool abandon_old = false) {
  s.programs.clear();  // their objects go with the old context
  s.sample_program = 0;
  s.empty_vertex_array = 0;
  s.facing_program = 0;
  s.facing_framebuffer = 0;
  s.facing_renderbuffer = 0;
  s.framebuffer = Framebuffer{};
  s.fallbacks_created = 0;
  s.debug_errors.clear();
  if (abandon_old) {
    s.context->abandon();
  } else {
    s.context->renew();
  }
  s.context->makeCurrent();
  s.gl.load(s.context->loader());
  enableDebugOutput(s);
  checkGl(s, "context creation");
}

// The GL state of a fresh context for everything renderLocked does not set itself.
void resetReusedContext(Session& s) {
  const gl::Functions& gl = s.gl;
  s.context->makeCurrent();
  s.debug_errors.clear();
  while (gl.GetError() != GL_NO_ERROR) {
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
  gl.UseProgram(0);
  gl.BindVertexArray(0);
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  gl.DepthMask(GL_TRUE);
  gl.DepthFunc(GL_LESS);
  gl.Disablei(GL_BLEND, 0);
  gl.Disablei(GL_BLEND, 1);
  gl.BlendFunc(GL_ONE, GL_ZERO);
  checkGl(s, "context reuse");
}

// Returns the session for spec, made current on this thread.
Session& acquireSession(const GlSpec& spec) {
  // A missing GPU is the answer for an egl-device spec, whatever else this process runs.
  if (spec.platform == GlSpec::Platform::EglDevice) gl::findEglDevice(spec.device);
  if (g_session == nullptr) {
    g_session = createSession(spec).release();
    g_session->context_use = "new";
    return *g_session;
  }
  const Session& have = *g_session;
  if (have.spec.platform != spec.platform || have.spec.mesa_dir != spec.mesa_dir ||
      (spec.platform == GlSpec::Platform::EglDevice && have.spec.device != spec.device)) {
    throw BackendError(fmt::format(
        "this process already renders with {} ({}); one GL provider per process: run {} in its "
        "own process",
        toString(have.spec), have.driver, toString(spec)));
  }
  if (!spec.driver.empty() && spec.driver != have.driver) {
    throw BackendError(fmt::format(
        "asked for {}, but this process already loaded {} (GALLIUM_DRIVER is read once per "
        "process): run {} in its own process",
        spec.driver, have.driver, toString(spec)));
  }
  Session& s = *g_session;
  const bool reuse = reusesContext(s);
  s.context_use = !reuse ? "new" : s.render_unfinished ? "replaced" : "reused";
  if (!reuse) {
    renewContext(s);
  } else if (s.render_unfinished) {
    // The last render threw halfway: its state is unknown, so the next starts from a new
    // context. Destroying the old one is what zink on Mesa 22 cannot take: there it is left
    // allocated (one per failed render).
    s.render_unfinished = false;
    renewContext(s, /*abandon_old=*/keepsOneContext(s));
  } else {
    resetReusedContext(s);
  }
  return s;
}

// A shader's or program's info log (`get_iv` and `get_log`: the glGet*iv and glGet*InfoLog
// of its kind) on one line: the report shows the first error, the compiler's newlines
// become ';'.
template <typename GetIv, typename GetLog>
std::string oneLineLog(GLuint id, GetIv get_iv, GetLog get_log) {
  GLint length = 0;
  get_iv(id, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  get_log(id, length, nullptr, log.data());
  log.resize(std::strlen(log.c_str()));
  while (!log.empty() && (log.back() == '\n' || log.back() == ' ')) log.pop_back();
  for (char& c : log) c = c == '\n' ? ';' : c;
  return log;
}

GLuint compileShader(const gl::Functions& gl, GLenum stage, const std::string& source) {
  const GLuint shader = gl.CreateShader(stage);
  const char* text = source.c_str();
  gl.ShaderSource(shader, 1, &text, nullptr);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return shader;
  const std::string log = oneLineLog(shader, gl.GetShaderiv, gl.GetShaderInfoLog);
  gl.DeleteShader(shader);
  throw BackendError(fmt::format("{} shader does not compile: {}",
                                 stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log));
}

// A program linked from the two sources (their shaders deleted), or BackendError naming
// `what` with the linker's log on one line.
GLuint linkProgram(const gl::Functions& gl, const std::string& vertex, const std::string& fragment,
                   std::string_view what) {
  const GLuint vs = compileShader(gl, GL_VERTEX_SHADER, vertex);
  GLuint fs = 0;
  try {
    fs = compileShader(gl, GL_FRAGMENT_SHADER, fragment);
  } catch (...) {
    gl.DeleteShader(vs);
    throw;
  }
  const GLuint id = gl.CreateProgram();
  gl.AttachShader(id, vs);
  gl.AttachShader(id, fs);
  gl.LinkProgram(id);
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(id, GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return id;
  const std::string log = oneLineLog(id, gl.GetProgramiv, gl.GetProgramInfoLog);
  gl.DeleteProgram(id);
  throw BackendError(fmt::format("{} does not link: {}", what, log));
}

// The program `id` as its binary gives it back: a new program object made from
// glGetProgramBinary's bytes; `id` is deleted. The same program when there is no binary or
// it does not load. Why: Mesa's on-disk shader cache keys llvmpipe's JIT-compiled state
// variants by the program's NIR, and a program linked from source and the same program
// found in Mesa's GLSL cache (every later process) hand the driver different NIR, so the
// variants a first run compiled were never found again and a second run compiled them all
// anew (gen200 on a new cache: 22 s, 16.7 s, then 2.1 s). Through its binary, every process
// draws with the cached form, and the second run finds the first one's variants
// (docs/performance.md, "Mesa's shader cache").
GLuint throughBinary(Session& s, GLuint id) {
  const gl::Functions& gl = s.gl;
  if (gl.GetProgramBinary == nullptr) return id;
  GLint length = 0;
  gl.GetProgramiv(id, GL_PROGRAM_BINARY_LENGTH, &length);
  if (length <= 0) return id;
  std::vector<std::byte> bytes(static_cast<std::size_t>(length));
  GLenum format = 0;
  gl.GetProgramBinary(id, length, nullptr, &format, bytes.data());
  const GLuint copy = gl.CreateProgram();
  gl.ProgramBinary(copy, format, bytes.data(), length);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(copy, GL_LINK_STATUS, &ok);
  if (gl.GetError() != GL_NO_ERROR || ok != GL_TRUE) {
    gl.DeleteProgram(copy);
    s.debug_errors.clear();
    return id;
  }
  gl.DeleteProgram(id);
  return copy;
}

const Program& programFor(Session& s, int max_lights, const gl::testing::Faults& faults,
                          bool shadows) {
  gl::ShaderFaults shader_faults;
  shader_faults.depth_bias = faults.depth_bias_steps != 0;
  shader_faults.shift_x = faults.shift_x_px != 0.0;
  shader_faults.compile_error = faults.shader_compile_error;
  shader_faults.texel_offset = faults.texel_offset != 0.0;
  shader_faults.lod_weight = faults.lod_weight_inverted;
  shader_faults.shadow_shift = faults.shadow_shift != 0.0;
  gl::ProgramSource source = gl::programSource(max_lights, shader_faults, shadows);
  const gl::testing::Hooks& hooks = gl::testing::hooks();
  if (!hooks.vertex_shader.empty()) source.vertex = hooks.vertex_shader;
  if (!hooks.fragment_shader.empty()) source.fragment = hooks.fragment_shader;
  std::string key = source.vertex + '\0' + source.fragment;
  if (hooks.program_from_source) key += std::string(1, '\0') + "from source";
  if (auto it = s.programs.find(key); it != s.programs.end()) {
    s.program_use = "reused";
    s.program_binary = it->second.from_binary;
    return it->second;
  }
  s.program_use = "compiled";

  const gl::Functions& gl = s.gl;
  const GLuint id = linkProgram(gl, source.vertex, source.fragment, "shader program");
  Program p;
  p.id = hooks.program_from_source ? id : throughBinary(s, id);
  p.from_binary = p.id != id;
  s.program_binary = p.from_binary;
  p.max_lights = max_lights;
  auto loc = [&](const char* name) { return gl.GetUniformLocation(p.id, name); };
  p.view_projection = loc("u_view_projection");
  p.shading = loc("u_shading");
  p.eye = loc("u_eye");
  p.ambient_light = loc("u_ambient_light");
  p.light_count = loc("u_light_count");
  p.light_type = loc("u_light_type");
  p.light_position = loc("u_light_position");
  p.light_direction = loc("u_light_direction");
  p.light_color = loc("u_light_color");
  p.light_intensity = loc("u_light_intensity");
  p.specular_model = loc("u_specular_model");
  p.attenuation = loc("u_attenuation");
  p.material_ambient = loc("u_material_ambient");
  p.material_diffuse = loc("u_material_diffuse");
  p.material_specular = loc("u_material_specular");
  p.shininess = loc("u_shininess");
  p.opacity = loc("u_opacity");
  p.has_texture = loc("u_has_texture");
  p.texture = loc("u_texture");
  p.fault_depth_bias = loc("u_fault_depth_bias");
  p.fault_shift_ndc = loc("u_fault_shift_ndc");
  p.fault_texel_offset = loc("u_fault_texel_offset");
  p.fault_lod_bias = loc("u_fault_lod_bias");
  p.fault_shadow_shift = loc("u_fault_shadow_shift");
  p.shadow_map = loc("u_shadow_map");
  p.shadow_matrix = loc("u_shadow_matrix");
  p.shadow_bias = loc("u_shadow_bias");
  p.light_shadowed = loc("u_light_shadowed");
  return s.programs.emplace(key, p).first->second;
}

// GL objects of one render, deleted on every exit path (the context is still current).
struct RenderObjects {
  const gl::Functions& gl;
  GLuint vertex_buffer = 0;
  GLuint vertex_array = 0;
  std::vector<GLuint> textures;

  explicit RenderObjects(const gl::Functions& functions) : gl(functions) {}
  RenderObjects(const RenderObjects&) = delete;
  RenderObjects& operator=(const RenderObjects&) = delete;
  ~RenderObjects() {
    if (!textures.empty())
      gl.DeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
    if (vertex_array != 0) gl.DeleteVertexArrays(1, &vertex_array);
    if (vertex_buffer != 0) gl.DeleteBuffers(1, &vertex_buffer);
    gl.GetError();  // cleanup after a failure must not leak an error into the next call
  }
};

struct AttachmentFormat {
  GLenum internal;
  const char* name;
};

AttachmentFormat colorFormat(ColorFormat f) {
  return f == ColorFormat::RGBA8 ? AttachmentFormat{GL_RGBA8, "rgba8"}
                                 : AttachmentFormat{GL_RGBA32F, "rgba32f"};
}

AttachmentFormat depthFormat(DepthFormat f) {
  switch (f) {
    case DepthFormat::D16:
      return {GL_DEPTH_COMPONENT16, "d16"};
    case DepthFormat::D24:
      return {GL_DEPTH_COMPONENT24, "d24"};
    case DepthFormat::D32F:
      return {GL_DEPTH_COMPONENT32F, "d32f"};
  }
  return {GL_DEPTH_COMPONENT24, "d24"};
}

void deleteFramebuffer(const gl::Functions& gl, Framebuffer& fb) {
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (fb.framebuffer != 0) gl.DeleteFramebuffers(1, &fb.framebuffer);
  gl.DeleteRenderbuffers(4, fb.renderbuffers);
  fb = Framebuffer{};
}

// Allocates colour (RGBA32F/RGBA8), ids (R32UI) and depth attachments and checks that the
// driver gave exactly the asked formats (no silent substitution).
void createFramebuffer(const gl::Functions& gl, Framebuffer& fb, const Scene& scene) {
  const AttachmentFormat color = colorFormat(scene.state.color_format);
  AttachmentFormat depth = depthFormat(scene.state.depth_format);
  const bool stencil = scene.state.stencil_format == StencilFormat::S8;
  gl.GenFramebuffers(1, &fb.framebuffer);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fb.framebuffer);
  gl.GenRenderbuffers(4, fb.renderbuffers);
  GLenum internal[4] = {color.internal, GL_R32UI, depth.internal, GL_STENCIL_INDEX8};
  GLenum attachment[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_DEPTH_ATTACHMENT,
                          GL_STENCIL_ATTACHMENT};
  int count = 3;
  // A stencil buffer: packed with d24 and d32f (the formats GL requires); beside d16 as a
  // separate GL_STENCIL_INDEX8 attachment, which a driver may refuse (unsupported).
  if (stencil && scene.state.depth_format == DepthFormat::D24) {
    internal[2] = GL_DEPTH24_STENCIL8;
    attachment[2] = GL_DEPTH_STENCIL_ATTACHMENT;
    depth.name = "d24 + s8";
  } else if (stencil && scene.state.depth_format == DepthFormat::D32F) {
    internal[2] = GL_DEPTH32F_STENCIL8;
    attachment[2] = GL_DEPTH_STENCIL_ATTACHMENT;
    depth.name = "d32f + s8";
  } else if (stencil) {
    count = 4;
    depth.name = "d16 + s8";
  }
  for (int i = 0; i < count; ++i) {
    gl.BindRenderbuffer(GL_RENDERBUFFER, fb.renderbuffers[i]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, internal[i], scene.width, scene.height);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, attachment[i], GL_RENDERBUFFER, fb.renderbuffers[i]);
  }
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    const std::string what = fmt::format(
        "framebuffer incomplete: {} (colour {}, ids r32ui, depth {}, {}x{})",
        framebufferStatusName(status), color.name, depth.name, scene.width, scene.height);
    // A combination of formats the driver refuses (d16 with a separate s8, for Mesa) is
    // a limit of the driver, reported as not supported, not a failure.
    if (status == GL_FRAMEBUFFER_UNSUPPORTED) throw NotSupportedError(what);
    throw BackendError(what);
  }
  auto query = [&](GLenum att, GLenum pname) {
    GLint v = 0;
    gl.GetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, att, pname, &v);
    return v;
  };
  const int depth_bits = query(GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE);
  const int depth_type = query(GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE);
  const int want_bits =
      scene.state.depth_format == DepthFormat::D32F ? 32 : depthBits(scene.state.depth_format);
  const int want_type =
      scene.state.depth_format == DepthFormat::D32F ? GL_FLOAT : GL_UNSIGNED_NORMALIZED;
  if (depth_bits != want_bits || depth_type != want_type) {
    throw BackendError(
        fmt::format("asked for a {} depth buffer, the driver gave {} bits of type 0x{:x}",
                    depth.name, depth_bits, depth_type));
  }
  const int red_bits = query(GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE);
  const int want_red = scene.state.color_format == ColorFormat::RGBA8 ? 8 : 32;
  if (red_bits != want_red) {
    throw BackendError(fmt::format("asked for an {} colour buffer, the driver gave {} red bits",
                                   color.name, red_bits));
  }
  fb.width = scene.width;
  fb.height = scene.height;
  if (stencil) {
    const int stencil_bits = query(GL_STENCIL_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE);
    if (stencil_bits != 8)
      throw BackendError(
          fmt::format("asked for an s8 stencil buffer, the driver gave {} bits", stencil_bits));
  }
  fb.color = scene.state.color_format;
  fb.depth = scene.state.depth_format;
  fb.stencil = scene.state.stencil_format;
}

// Binds an FBO for the scene, reusing the last one when size and formats match.
void bindFramebuffer(Session& s, const Scene& scene) {
  const gl::Functions& gl = s.gl;
  Framebuffer& fb = s.framebuffer;
  const bool reusable = fb.framebuffer != 0 && fb.width == scene.width &&
                        fb.height == scene.height && fb.color == scene.state.color_format &&
                        fb.depth == scene.state.depth_format &&
                        fb.stencil == scene.state.stencil_format;
  if (reusable) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, fb.framebuffer);
  } else {
    deleteFramebuffer(gl, fb);
    try {
      createFramebuffer(gl, fb, scene);
      checkGl(s, "framebuffer setup");
    } catch (...) {
      deleteFramebuffer(gl, fb);
      gl.GetError();
      throw;
    }
  }
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, draw_buffers);
}

void uploadVertices(RenderObjects& o, const gl::VertexData& data) {
  const gl::Functions& gl = o.gl;
  gl.GenVertexArrays(1, &o.vertex_array);
  gl.BindVertexArray(o.vertex_array);
  gl.GenBuffers(1, &o.vertex_buffer);
  gl.BindBuffer(GL_ARRAY_BUFFER, o.vertex_buffer);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.vertices.size() * sizeof(gl::Vertex)),
                data.vertices.empty() ? nullptr : data.vertices.data(), GL_STATIC_DRAW);
  constexpr auto kStride = static_cast<GLsizei>(sizeof(gl::Vertex));
  // With a buffer bound, GL takes attribute offsets disguised as pointers.
  auto offset = [](std::size_t bytes) {
    return reinterpret_cast<const void*>(bytes);  // NOLINT(performance-no-int-to-ptr)
  };
  auto floats = [&](GLuint location, GLint size, std::size_t bytes) {
    gl.EnableVertexAttribArray(location);
    gl.VertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, kStride, offset(bytes));
  };
  floats(gl::kAttribWorldPosition, 3, offsetof(gl::Vertex, world_position));
  floats(gl::kAttribWorldNormal, 3, offsetof(gl::Vertex, world_normal));
  floats(gl::kAttribUv, 2, offsetof(gl::Vertex, uv));
  gl.EnableVertexAttribArray(gl::kAttribPrimitiveId);
  gl.VertexAttribIPointer(gl::kAttribPrimitiveId, 1, GL_UNSIGNED_INT, kStride,
                          offset(offsetof(gl::Vertex, primitive_id)));
  floats(gl::kAttribFaceCentroid, 3, offsetof(gl::Vertex, face_centroid));
  floats(gl::kAttribFaceNormal, 3, offsetof(gl::Vertex, face_normal));
}

// One GL texture per distinct rc::Texture; returns the name for each material (0: none).
std::vector<GLuint> uploadTextures(RenderObjects& o, const Scene& scene, int max_texture_size,
                                   const gl::testing::Faults& faults,
                                   const std::map<std::string, GLuint>& target_textures) {
  const gl::Functions& gl = o.gl;
  std::map<const Texture*, GLuint> by_texture;
  std::vector<GLuint> per_material(scene.materials.size(), 0);
  const RenderState& st = scene.state;
  constexpr std::array<GLint, 6> kMinFilters{GL_NEAREST,
                                             GL_LINEAR,
                                             GL_NEAREST_MIPMAP_NEAREST,
                                             GL_LINEAR_MIPMAP_NEAREST,
                                             GL_NEAREST_MIPMAP_LINEAR,
                                             GL_LINEAR_MIPMAP_LINEAR};
  const GLint min_filter = kMinFilters.at(static_cast<std::size_t>(minFilter(st)));
  const GLint mag_filter = magFilter(st) == TextureFilter::Linear ? GL_LINEAR : GL_NEAREST;
  const GLint wrap = st.texture_wrap == TextureWrap::Clamp            ? GL_CLAMP_TO_EDGE
                     : st.texture_wrap == TextureWrap::MirroredRepeat ? GL_MIRRORED_REPEAT
                                                                      : GL_REPEAT;
  // Every level of the chain both renderers sample (fixtures/mipmaps.h) when the level of
  // detail matters; level 0 alone otherwise, as before.
  const bool levels = lodSampling(st);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.ActiveTexture(GL_TEXTURE0);
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    // A colour target an earlier pass drew: its own texture, one level, sampled with the
    // scene's filters and wrap.
    if (const std::string& name = scene.materials[m].texture_target; !name.empty()) {
      const auto it = target_textures.find(name);
      if (it == target_textures.end()) continue;
      gl.BindTexture(GL_TEXTURE_2D, it->second);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                       minFilter(st) == MinFilter::Linear ? GL_LINEAR : GL_NEAREST);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, mag_filter);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
      per_material[m] = it->second;
      continue;
    }
    const Texture* t = scene.materials[m].texture.get();
    if (t == nullptr) continue;
    const bool explicit_levels = !scene.materials[m].texture_levels.empty();
    if (auto it = by_texture.find(t); it != by_texture.end() && !explicit_levels) {
      per_material[m] = it->second;
      continue;
    }
    if (t->width > max_texture_size || t->height > max_texture_size) {
      throw BackendError(fmt::format("texture {} is {}x{}, GL_MAX_TEXTURE_SIZE is {}",
                                     t->path.string(), t->width, t->height, max_texture_size));
    }
    GLuint name = 0;
    gl.GenTextures(1, &name);
    o.textures.push_back(name);
    gl.BindTexture(GL_TEXTURE_2D, name);
    // Row 0 of rc::Texture is v = 0, which is also GL's first row: no flip.
    const std::vector<std::shared_ptr<const Texture>> chain =
        levels ? mipChain(scene.materials[m]) : std::vector<std::shared_ptr<const Texture>>{};
    if (levels) {
      for (std::size_t k = 0; k < chain.size(); ++k)
        gl.TexImage2D(GL_TEXTURE_2D, static_cast<GLint>(k), GL_RGBA8, chain[k]->width,
                      chain[k]->height, 0, GL_RGBA, GL_UNSIGNED_BYTE, chain[k]->rgba.data());
    } else {
      gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, t->width, t->height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                    t->rgba.data());
    }
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, levels ? min_filter : mag_filter);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, mag_filter);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL,
                     levels ? static_cast<GLint>(chain.size()) - 1 : 0);
    if (levels) {
      gl.TexParameterf(GL_TEXTURE_2D, GL_TEXTURE_LOD_BIAS,
                       static_cast<GLfloat>(st.lod_bias + faults.lod_shift));
      gl.TexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MIN_LOD, static_cast<GLfloat>(st.min_lod));
      gl.TexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_LOD, static_cast<GLfloat>(st.max_lod));
    }
    by_texture.emplace(t, name);
    per_material[m] = name;
  }
  return per_material;
}

glm::vec3 toFloat(const glm::dvec3& v) { return glm::vec3(v); }

void setSceneUniforms(const gl::Functions& gl, const Program& p, const Scene& scene,
                      const gl::testing::Faults& faults) {
  const glm::mat4 view_projection(viewProjectionMatrix(scene));
  gl.UseProgram(p.id);
  gl.UniformMatrix4fv(p.view_projection, 1, GL_FALSE, glm::value_ptr(view_projection));
  const RenderState& st = scene.state;
  gl.Uniform1i(p.shading, gl::uniformValue(st.shading));
  gl.Uniform1i(p.specular_model, gl::uniformValue(st.specular_model));
  gl.Uniform1i(p.attenuation, gl::uniformValue(st.attenuation));
  gl.Uniform3fv(p.eye, 1, glm::value_ptr(toFloat(scene.camera.eye)));
  gl.Uniform3fv(p.ambient_light, 1, glm::value_ptr(toFloat(scene.ambient_light)));
  const auto count = static_cast<GLsizei>(scene.lights.size());
  gl.Uniform1i(p.light_count, count);
  gl.Uniform1i(p.texture, 0);
  if (p.shadow_map >= 0) gl.Uniform1i(p.shadow_map, 1);
  if (p.fault_shadow_shift >= 0)
    gl.Uniform1f(p.fault_shadow_shift, static_cast<GLfloat>(faults.shadow_shift));
  if (p.fault_shift_ndc >= 0) {
    gl.Uniform1f(p.fault_shift_ndc, static_cast<GLfloat>(2.0 * faults.shift_x_px / scene.width));
  }
  if (p.fault_texel_offset >= 0) {
    gl.Uniform1f(p.fault_texel_offset, static_cast<GLfloat>(faults.texel_offset));
  }
  if (p.fault_lod_bias >= 0) {
    gl.Uniform1f(p.fault_lod_bias, static_cast<GLfloat>(scene.state.lod_bias + faults.lod_shift));
  }
  if (p.fault_depth_bias >= 0) {
    const int bits = depthBits(scene.state.depth_format);  // d32f: one step is 2^-24
    const double step = bits > 0 ? 1.0 / (std::ldexp(1.0, bits) - 1.0) : std::ldexp(1.0, -24);
    gl.Uniform1f(p.fault_depth_bias, static_cast<GLfloat>(faults.depth_bias_steps * step));
  }
  if (count == 0) return;
  std::vector<GLint> type;
  std::vector<glm::vec3> position, direction, color;
  std::vector<GLfloat> intensity;
  for (const Light& l : scene.lights) {
    type.push_back(gl::uniformValue(l.type));
    position.push_back(toFloat(l.position));
    direction.push_back(toFloat(l.direction));
    color.push_back(toFloat(l.color));
    intensity.push_back(static_cast<GLfloat>(l.intensity * faults.light_scale));
  }
  gl.Uniform1iv(p.light_type, count, type.data());
  gl.Uniform3fv(p.light_position, count, glm::value_ptr(position[0]));
  gl.Uniform3fv(p.light_direction, count, glm::value_ptr(direction[0]));
  gl.Uniform3fv(p.light_color, count, glm::value_ptr(color[0]));
  gl.Uniform1fv(p.light_intensity, count, intensity.data());
}

// A material's shadow lookup as GL draws it: the map's depth texture with its compare
// state, the matrix into it, the bias and which lights it darkens.
struct MaterialShadow {
  GLuint texture = 0;  // 0: no lookup
  glm::mat4 matrix{1.0f};
  GLint compare = GL_LEQUAL;
  GLint filter = GL_NEAREST;
  GLfloat bias = 0.0f;
  std::vector<GLint> shadowed;  // per light: 1 where lights[i].shadow_map is the map
};

void setMaterialUniforms(const gl::Functions& gl, const Program& p, const Material& m,
                         GLuint texture, const MaterialShadow* shadow) {
  if (p.light_shadowed >= 0) {
    const MaterialShadow none;
    const MaterialShadow& sh = shadow != nullptr && shadow->texture != 0 ? *shadow : none;
    std::vector<GLint> flags = sh.shadowed;
    flags.resize(static_cast<std::size_t>(std::max(p.max_lights, 1)), 0);
    gl.Uniform1iv(p.light_shadowed, p.max_lights, flags.data());
    if (sh.texture != 0) {
      gl.ActiveTexture(GL_TEXTURE1);
      gl.BindTexture(GL_TEXTURE_2D, sh.texture);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, sh.compare);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, sh.filter);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, sh.filter);
      gl.ActiveTexture(GL_TEXTURE0);
      gl.UniformMatrix4fv(p.shadow_matrix, 1, GL_FALSE, glm::value_ptr(sh.matrix));
      gl.Uniform1f(p.shadow_bias, sh.bias);
    }
  }
  gl.Uniform3fv(p.material_ambient, 1, glm::value_ptr(toFloat(m.ambient)));
  gl.Uniform3fv(p.material_diffuse, 1, glm::value_ptr(toFloat(m.diffuse)));
  gl.Uniform3fv(p.material_specular, 1, glm::value_ptr(toFloat(m.specular)));
  gl.Uniform1f(p.shininess, static_cast<GLfloat>(m.shininess));
  gl.Uniform1f(p.opacity, static_cast<GLfloat>(m.opacity));
  gl.Uniform1i(p.has_texture, texture != 0 ? 1 : 0);
  gl.BindTexture(GL_TEXTURE_2D, texture);
}

// Fixed-function state that never changes between passes: GL conventions of DESIGN.md.
void setFixedState(const gl::Functions& gl, const Scene& scene) {
  gl.Viewport(0, 0, scene.width, scene.height);
  gl.DepthRange(0.0, 1.0);
  for (GLenum cap :
       {GL_DITHER, GL_MULTISAMPLE, GL_FRAMEBUFFER_SRGB, GL_DEPTH_CLAMP, GL_SCISSOR_TEST,
        GL_STENCIL_TEST, GL_POLYGON_OFFSET_FILL, GL_SAMPLE_ALPHA_TO_COVERAGE, GL_RASTERIZER_DISCARD,
        GL_PRIMITIVE_RESTART, GL_LINE_SMOOTH, GL_PROGRAM_POINT_SIZE}) {
    gl.Disable(cap);
  }
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  gl.Enable(GL_DEPTH_TEST);  // also for "no depth test": ALWAYS keeps depth writes on
  gl.BlendEquation(GL_FUNC_ADD);
  gl.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  gl.Disablei(GL_BLEND, 1);  // R32UI ids never blend (GL ignores blending on integer buffers)
}

GLenum glCompare(CompareFunc f) {
  constexpr std::array<GLenum, 8> kFuncs{GL_NEVER,   GL_LESS,     GL_EQUAL,  GL_LEQUAL,
                                         GL_GREATER, GL_NOTEQUAL, GL_GEQUAL, GL_ALWAYS};
  return kFuncs.at(static_cast<std::size_t>(f));
}
GLenum glStencilOp(StencilOp op) {
  constexpr std::array<GLenum, 8> kOps{GL_KEEP,      GL_ZERO, GL_REPLACE,   GL_INCR,
                                       GL_INCR_WRAP, GL_DECR, GL_DECR_WRAP, GL_INVERT};
  return kOps.at(static_cast<std::size_t>(op));
}
GLenum glBlendEquationOf(BlendEquation e) {
  constexpr std::array<GLenum, 5> kEquations{GL_FUNC_ADD, GL_FUNC_SUBTRACT,
                                             GL_FUNC_REVERSE_SUBTRACT, GL_MIN, GL_MAX};
  return kEquations.at(static_cast<std::size_t>(e));
}
GLenum glBlendFactorOf(BlendFactor f) {
  constexpr std::array<GLenum, 15> kFactors{GL_ZERO,
                                            GL_ONE,
                                            GL_SRC_COLOR,
                                            GL_ONE_MINUS_SRC_COLOR,
                                            GL_DST_COLOR,
                                            GL_ONE_MINUS_DST_COLOR,
                                            GL_SRC_ALPHA,
                                            GL_ONE_MINUS_SRC_ALPHA,
                                            GL_DST_ALPHA,
                                            GL_ONE_MINUS_DST_ALPHA,
                                            GL_CONSTANT_COLOR,
                                            GL_ONE_MINUS_CONSTANT_COLOR,
                                            GL_CONSTANT_ALPHA,
                                            GL_ONE_MINUS_CONSTANT_ALPHA,
                                            GL_SRC_ALPHA_SATURATE};
  return kFactors.at(static_cast<std::size_t>(f));
}

// The test-only faults of the fragment operations (gl_testing.h).
CompareFunc invertedFunc(CompareFunc f) {
  constexpr std::array<CompareFunc, 8> kInverted{
      CompareFunc::Always, CompareFunc::Greater, CompareFunc::NotEqual, CompareFunc::GEqual,
      CompareFunc::Less,   CompareFunc::Equal,   CompareFunc::LEqual,   CompareFunc::Never};
  return kInverted.at(static_cast<std::size_t>(f));
}
StencilOp shiftedOp(StencilOp op) {
  return kStencilOps.at((static_cast<std::size_t>(op) + 1) % kStencilOps.size());
}

void setStencilFace(const gl::Functions& gl, GLenum face, const StencilFace& f,
                    const gl::testing::Faults& faults) {
  auto op = [&](StencilOp o) { return glStencilOp(faults.stencil_op_shifted ? shiftedOp(o) : o); };
  gl.StencilFuncSeparate(face, glCompare(f.func), f.ref, f.read_mask);
  gl.StencilOpSeparate(face, op(f.fail), op(f.depth_fail), op(f.pass));
  gl.StencilMaskSeparate(face, f.write_mask);
}

// One pass's fixed-function state (DrawPass): culling, depth, stencil, scissor, offset,
// blending and the colour mask of the colour attachment (never the ids').
void setPassState(const gl::Functions& gl, const DrawPass& pass,
                  const gl::testing::Faults& faults) {
  if (pass.cull == Cull::None) {
    gl.Disable(GL_CULL_FACE);
  } else {
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(pass.cull == Cull::Back ? GL_BACK : GL_FRONT);
  }
  gl.FrontFace(pass.front_face == FrontFace::CW ? GL_CW : GL_CCW);
  gl.DepthFunc(
      glCompare(faults.depth_func_inverted ? invertedFunc(pass.depth_func) : pass.depth_func));
  gl.DepthMask(pass.depth_write ? GL_TRUE : GL_FALSE);
  const FragmentOps& ops = pass.ops;
  // Lines and points: the widths and the polygon mode (polygon_offset is
  // GL_POLYGON_OFFSET_FILL alone: polygons drawn as lines or points are not offset).
  constexpr std::array<GLenum, 3> kModes{GL_FILL, GL_LINE, GL_POINT};
  gl.PolygonMode(GL_FRONT_AND_BACK, kModes.at(static_cast<std::size_t>(ops.polygon_mode)));
  gl.LineWidth(static_cast<GLfloat>(ops.line_width));
  gl.PointSize(static_cast<GLfloat>(ops.point_size));
  gl.DepthRange(ops.depth_range.x, ops.depth_range.y);
  if (ops.polygon_offset) {
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(static_cast<GLfloat>(ops.polygon_offset->factor),
                     static_cast<GLfloat>(ops.polygon_offset->units));
  } else {
    gl.Disable(GL_POLYGON_OFFSET_FILL);
  }
  if (ops.stencil) {
    gl.Enable(GL_STENCIL_TEST);
    setStencilFace(gl, GL_FRONT, ops.stencil->front, faults);
    setStencilFace(gl, GL_BACK, ops.stencil->back, faults);
  } else {
    gl.Disable(GL_STENCIL_TEST);
  }
  if (ops.scissor) {
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(ops.scissor->x + faults.scissor_shift, ops.scissor->y, ops.scissor->width,
               ops.scissor->height);
  } else {
    gl.Disable(GL_SCISSOR_TEST);
  }
  const auto& m = ops.color_mask;
  gl.ColorMaski(0, m[0] ? GL_TRUE : GL_FALSE, m[1] ? GL_TRUE : GL_FALSE, m[2] ? GL_TRUE : GL_FALSE,
                m[3] ? GL_TRUE : GL_FALSE);
  if (!pass.blend) {
    gl.Disablei(GL_BLEND, 0);
    return;
  }
  gl.Enablei(GL_BLEND, 0);
  if (pass.blend_function) {
    const BlendFunction& b = ops.blend_function;
    gl.BlendEquationSeparate(glBlendEquationOf(b.equation), glBlendEquationOf(b.equation_alpha));
    const BlendFactor src =
        faults.blend_function_shifted
            ? kBlendFactors.at((static_cast<std::size_t>(b.src) + 1) % kBlendFactors.size())
            : b.src;
    gl.BlendFuncSeparate(glBlendFactorOf(src), glBlendFactorOf(b.dst), glBlendFactorOf(b.src_alpha),
                         glBlendFactorOf(b.dst_alpha));
    gl.BlendColor(static_cast<GLfloat>(b.constant.r), static_cast<GLfloat>(b.constant.g),
                  static_cast<GLfloat>(b.constant.b), static_cast<GLfloat>(b.constant.a));
  } else {
    gl.BlendEquation(GL_FUNC_ADD);
    gl.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  }
  // The test-only fault blend_factor: the classic wrong blend functions.
  using Blend = gl::testing::Faults::Blend;
  if (faults.blend_factor == Blend::One) gl.BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  if (faults.blend_factor == Blend::Swapped) gl.BlendFunc(GL_ONE_MINUS_SRC_ALPHA, GL_SRC_ALPHA);
}

// Back to the state the readback draws expect (multisampling's sample copies).
void resetPassState(const gl::Functions& gl) {
  for (GLenum cap : {GL_SCISSOR_TEST, GL_STENCIL_TEST, GL_POLYGON_OFFSET_FILL}) gl.Disable(cap);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  gl.DepthRange(0.0, 1.0);
}

void clearFramebuffer(const gl::Functions& gl, const Scene& scene) {
  gl.DepthMask(GL_TRUE);
  resetPassState(gl);
  const glm::vec4 clear_color(scene.clear_color);
  gl.ClearBufferfv(GL_COLOR, 0, glm::value_ptr(clear_color));
  const GLuint zero_ids[4] = {0, 0, 0, 0};
  gl.ClearBufferuiv(GL_COLOR, 1, zero_ids);
  const auto clear_depth = static_cast<GLfloat>(scene.clear_depth);
  gl.ClearBufferfv(GL_DEPTH, 0, &clear_depth);
  if (scene.state.stencil_format != StencilFormat::None) {
    gl.StencilMask(0xff);
    const GLint clear_stencil = scene.clear_stencil;
    gl.ClearBufferiv(GL_STENCIL, 0, &clear_stencil);
  }
}

// Polygon offset's r as this driver applies it (GL leaves r to the implementation,
// docs/tolerances.md "Polygon offset"): a quad over the viewport at window depth 0.5 drawn
// with factor 0 and kOffsetProbeUnits units, its depth read back at one pixel. r is given
// in units of the format's minimum resolvable difference at that depth (the reference's
// r: one step of d16 or d24, 2^-24 for d32f in [0.5, 1)). Drawn into the scene's
// framebuffer before the scene; the caller clears it again.
constexpr double kOffsetProbeUnits = 1024.0;
constexpr std::size_t kOffsetProbeVertices = 6;

void appendOffsetProbe(gl::VertexData& data) {
  const float corners[kOffsetProbeVertices][2] = {{-1, -1}, {1, -1}, {1, 1},
                                                  {-1, -1}, {1, 1},  {-1, 1}};
  for (const auto& c : corners) {
    gl::Vertex& v = data.vertices.emplace_back();
    v = gl::Vertex{};
    v.world_position[0] = c[0];
    v.world_position[1] = c[1];
  }
}

double measureOffsetR(const gl::Functions& gl, const Program& p, const Scene& scene,
                      GLint first_vertex, const FallbackFlush& fallback) {
  const glm::mat4 identity(1.0f);
  gl.UniformMatrix4fv(p.view_projection, 1, GL_FALSE, glm::value_ptr(identity));
  DrawPass probe;
  probe.depth_func = DepthFunc::Always;
  probe.ops.polygon_offset = PolygonOffset{0.0, kOffsetProbeUnits};
  setPassState(gl, probe, gl::testing::Faults{});
  fallback.beforeDraw();
  gl.DrawArrays(GL_TRIANGLES, first_vertex, static_cast<GLsizei>(kOffsetProbeVertices));
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  double offset_steps = 0.0;  // the offset in steps of r_min
  switch (scene.state.depth_format) {
    case DepthFormat::D16: {
      GLushort q = 0;
      gl.ReadPixels(0, 0, 1, 1, GL_DEPTH_COMPONENT, GL_UNSIGNED_SHORT, &q);
      offset_steps = q - 0.5 * 65535.0;
      break;
    }
    case DepthFormat::D24: {
      GLuint v = 0;
      gl.ReadPixels(0, 0, 1, 1, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, &v);
      offset_steps = (v >> 8) - 0.5 * 16777215.0;
      break;
    }
    case DepthFormat::D32F: {
      GLfloat z = 0.0f;
      gl.ReadPixels(0, 0, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &z);
      offset_steps = std::ldexp(static_cast<double>(z) - 0.5, 24);
      break;
    }
  }
  const glm::mat4 view_projection(viewProjectionMatrix(scene));
  gl.UniformMatrix4fv(p.view_projection, 1, GL_FALSE, glm::value_ptr(view_projection));
  // To 1/64: the base depth's own rounding is half a step in kOffsetProbeUnits.
  return std::round(offset_steps / kOffsetProbeUnits * 64.0) / 64.0;
}

void drawPassesGl(const gl::Functions& gl, const Program& p, const Scene& scene,
                  const gl::VertexData& data, const std::vector<GLuint>& textures,
                  const std::vector<MaterialShadow>& shadows, const gl::testing::Faults& faults,
                  const FallbackFlush& fallback) {
  std::uint32_t bound_material = UINT32_MAX;
  for (const gl::PassRuns& pass : data.passes) {
    setPassState(gl, pass.state, faults);
    for (const gl::DrawRun& run : pass.runs) {
      if (run.material != bound_material) {
        setMaterialUniforms(gl, p, scene.materials[run.material], textures[run.material],
                            shadows.empty() ? nullptr : &shadows[run.material]);
        bound_material = run.material;
      }
      constexpr std::array<GLenum, 3> kPrimitives{GL_TRIANGLES, GL_LINES, GL_POINTS};
      fallback.beforeDraw();
      gl.DrawArrays(kPrimitives.at(static_cast<std::size_t>(pass.state.primitive)),
                    static_cast<GLint>(run.first_vertex), static_cast<GLsizei>(run.vertex_count));
    }
  }
}

// Swaps rows top <-> bottom in place: GL returns the bottom row first.
void flipRows(std::byte* data, std::size_t row_bytes, int height) {
  for (int top = 0, bottom = height - 1; top < bottom; ++top, --bottom) {
    std::swap_ranges(data + static_cast<std::size_t>(top) * row_bytes,
                     data + static_cast<std::size_t>(top + 1) * row_bytes,
                     data + static_cast<std::size_t>(bottom) * row_bytes);
  }
}

// Reads the bound read buffer (or depth) into dst, top row first: with
// GL_MESA_pack_invert (llvmpipe, softpipe) the driver writes the rows in that order in
// its one copy; elsewhere the rows are swapped afterwards.
void readRows(const gl::Functions& gl, bool inverted, int w, int h, GLenum format, GLenum type,
              void* dst, std::size_t row_bytes) {
  gl.ReadPixels(0, 0, w, h, format, type, dst);
  if (!inverted) flipRows(static_cast<std::byte*>(dst), row_bytes, h);
}

template <typename T>
T* scratchFor(std::vector<T>& scratch, std::size_t n) {
  if (scratch.size() < n) scratch.resize(n);
  return scratch.data();
}

// Reads colour, depth and ids straight into the Frame's buffers (no intermediate copy
// except for d16 and rgba8, which need converting). Stored depth q becomes q / (2^b - 1)
// like the reference; q * (1 / (2^b - 1)) in double rounds to the same float for every
// q (checked for all 2^24 and 2^16 values) and vectorises.
void readBack(Session& s, const Scene& scene, Frame& frame) {
  const gl::Functions& gl = s.gl;
  Scratch& scratch = s.scratch;
  const int w = scene.width;
  const int h = scene.height;
  const auto row = static_cast<std::size_t>(w);
  const std::size_t n = row * h;
  frame.width = w;
  frame.height = h;
  frame.color.resize(n * 4);
  frame.depth.resize(n);
  frame.id.resize(n);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  const bool inverted = gl.pack_invert && !gl::testing::hooks().ignore_pack_invert;
  if (inverted) gl.PixelStorei(GL_PACK_INVERT_MESA, GL_TRUE);

  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  if (scene.state.color_format == ColorFormat::RGBA8) {
    std::uint8_t* bytes = scratchFor(scratch.bytes, n * 4);
    readRows(gl, inverted, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bytes, row * 4);
    static const auto kUnorm8 = [] {
      std::array<float, 256> t{};
      for (int q = 0; q < 256; ++q) t[q] = static_cast<float>(q / 255.0);
      return t;
    }();
    float* dst = frame.color.data();
    for (std::size_t i = 0; i < n * 4; ++i) dst[i] = kUnorm8[bytes[i]];
  } else {
    readRows(gl, inverted, w, h, GL_RGBA, GL_FLOAT, frame.color.data(), row * 4 * sizeof(float));
  }

  // GL_UNSIGNED_INT scales a 24-bit value to 32 bits, so q = v >> 8 whether the driver
  // replicates bits or rounds (see docs/gl_backend.md "Readback"). The ids' buffer holds
  // the raw values until the ids are read.
  float* depth = frame.depth.data();
  switch (scene.state.depth_format) {
    case DepthFormat::D16: {
      std::uint16_t* q = scratchFor(scratch.halves, n);
      readRows(gl, inverted, w, h, GL_DEPTH_COMPONENT, GL_UNSIGNED_SHORT, q, row * 2);
      constexpr double kScale = 1.0 / 65535.0;
      for (std::size_t i = 0; i < n; ++i) depth[i] = static_cast<float>(q[i] * kScale);
      break;
    }
    case DepthFormat::D24: {
      std::uint32_t* v = frame.id.data();
      readRows(gl, inverted, w, h, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, v, row * 4);
      constexpr double kScale = 1.0 / 16777215.0;
      for (std::size_t i = 0; i < n; ++i) depth[i] = static_cast<float>((v[i] >> 8) * kScale);
      break;
    }
    case DepthFormat::D32F:
      readRows(gl, inverted, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depth, row * 4);
      break;
  }

  if (scene.state.stencil_format != StencilFormat::None) {
    std::uint8_t* bytes = scratchFor(scratch.bytes, n);
    readRows(gl, inverted, w, h, GL_STENCIL_INDEX, GL_UNSIGNED_BYTE, bytes, row);
    frame.stencil.assign(bytes, bytes + n);
  } else {
    frame.stencil.clear();
  }

  gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
  readRows(gl, inverted, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, frame.id.data(), row * 4);
  if (inverted) gl.PixelStorei(GL_PACK_INVERT_MESA, GL_FALSE);
}

// ---- multisampling ---------------------------------------------------------------------
// A multisampled scene draws into `framebuffer` here: colour in a multisample renderbuffer,
// ids (R32UI) and depth in multisample textures so that a shader can read every sample
// (glBlitFramebuffer gives one sample of an integer buffer and an implementation-defined
// mix of the depth samples). The colour resolves into the single-sample FBO by
// glBlitFramebuffer (the driver's own resolve, what applications get); the ids and depth
// of each sample are copied, one sample per pass, into the single-sample FBO's R32UI
// attachment and read back (depth as its stored integer for d16/d24, its bits for d32f).

// The samples this driver can give every attachment a multisampled render uses.
int maxUsableSamples(const gl::Functions& gl) {
  return std::min({glInteger(gl, GL_MAX_SAMPLES), glInteger(gl, GL_MAX_COLOR_TEXTURE_SAMPLES),
                   glInteger(gl, GL_MAX_DEPTH_TEXTURE_SAMPLES),
                   glInteger(gl, GL_MAX_INTEGER_SAMPLES)});
}

struct MultisampleTargets {
  const gl::Functions& gl;
  GLuint framebuffer = 0;
  GLuint color = 0;             // renderbuffer
  GLuint textures[2] = {0, 0};  // ids, depth
  explicit MultisampleTargets(const gl::Functions& functions) : gl(functions) {}
  MultisampleTargets(const MultisampleTargets&) = delete;
  MultisampleTargets& operator=(const MultisampleTargets&) = delete;
  ~MultisampleTargets() {
    if (framebuffer != 0) gl.DeleteFramebuffers(1, &framebuffer);
    if (color != 0) gl.DeleteRenderbuffers(1, &color);
    gl.DeleteTextures(2, textures);
    gl.GetError();
  }
};

void createMultisampleTargets(Session& s, const Scene& scene, MultisampleTargets& t) {
  const gl::Functions& gl = s.gl;
  const int samples = scene.state.samples;
  gl.GenFramebuffers(1, &t.framebuffer);
  gl.BindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
  gl.GenRenderbuffers(1, &t.color);
  gl.BindRenderbuffer(GL_RENDERBUFFER, t.color);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples,
                                    colorFormat(scene.state.color_format).internal, scene.width,
                                    scene.height);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, t.color);
  gl.GenTextures(2, t.textures);
  const GLenum internal[2] = {GL_R32UI, depthFormat(scene.state.depth_format).internal};
  const GLenum attachment[2] = {GL_COLOR_ATTACHMENT1, GL_DEPTH_ATTACHMENT};
  for (int i = 0; i < 2; ++i) {
    gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t.textures[i]);
    gl.TexImage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, samples, internal[i], scene.width,
                             scene.height, GL_TRUE);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, attachment[i], GL_TEXTURE_2D_MULTISAMPLE, t.textures[i],
                            0);
  }
  gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, 0);
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw BackendError(fmt::format("multisampled framebuffer incomplete: {} ({} samples)",
                                   framebufferStatusName(status), samples));
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, draw_buffers);
  checkGl(s, "multisampled framebuffer setup");
}

// The program that copies sample u_sample of the ids (u_what 0) or of the depth (u_what
// 1: the stored integer of d16/d24 as round(d * (2^b - 1)), the bits of d32f) to the
// R32UI attachment. A full-screen triangle from gl_VertexID (no vertex buffer).
GLuint sampleProgram(Session& s) {
  if (s.sample_program != 0) return s.sample_program;
  const gl::Functions& gl = s.gl;
  const std::string vertex = R"(#version 330 core
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";
  const std::string fragment = R"(#version 330 core
uniform usampler2DMS u_ids;
uniform sampler2DMS u_depth;
uniform int u_sample;
uniform int u_what;
uniform float u_depth_scale;  // 2^b - 1; 0: d32f
layout(location = 1) out uint o_value;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  if (u_what == 0) {
    o_value = texelFetch(u_ids, p, u_sample).r;
  } else {
    float d = texelFetch(u_depth, p, u_sample).r;
    o_value = u_depth_scale > 0.0 ? uint(floor(d * u_depth_scale + 0.5)) : floatBitsToUint(d);
  }
}
)";
  s.sample_program = linkProgram(gl, vertex, fragment, "the sample readback program");
  if (s.empty_vertex_array == 0) gl.GenVertexArrays(1, &s.empty_vertex_array);
  return s.sample_program;
}

// softpipe's triangle set-up keeps the facing of the last triangle it set up (even one culled
// after it) and hands it to the lines and points drawn after it: their two-sided stencil
// state and gl_FrontFacing (sp_setup.c sets setup->facing in triangle set-up only). A new
// context starts at 0, front; a reused one at whatever the last render's last triangle was
// (docs/results/findings.md, "softpipe: lines and points take the facing of the last
// triangle"). Before a render in a reused softpipe context one front-facing triangle with
// colour writes off, into a 1x1 framebuffer of its own, puts it back to front (a triangle in
// an empty scissor box never reaches the set-up).
void resetSetupFacing(Session& s) {
  if (gl::testing::hooks().no_facing_reset) return;
  const gl::Functions& gl = s.gl;
  if (s.facing_program == 0) {
    const std::string vertex = R"(#version 330 core
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 0.5 : -0.5, gl_VertexID == 2 ? 0.5 : -0.5);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";
    const std::string fragment = R"(#version 330 core
out vec4 o_color;
void main() { o_color = vec4(0.0); }
)";
    s.facing_program = linkProgram(gl, vertex, fragment, "the set-up facing program");
    gl.GenRenderbuffers(1, &s.facing_renderbuffer);
    gl.BindRenderbuffer(GL_RENDERBUFFER, s.facing_renderbuffer);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 1, 1);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
    gl.GenFramebuffers(1, &s.facing_framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, s.facing_framebuffer);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                               s.facing_renderbuffer);
  }
  if (s.empty_vertex_array == 0) gl.GenVertexArrays(1, &s.empty_vertex_array);
  gl.BindFramebuffer(GL_FRAMEBUFFER, s.facing_framebuffer);
  gl.Viewport(0, 0, 1, 1);
  gl.Disable(GL_SCISSOR_TEST);
  gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  gl.Disable(GL_CULL_FACE);
  gl.Disable(GL_RASTERIZER_DISCARD);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  gl.FrontFace(GL_CCW);  // the triangle is counter-clockwise: front
  gl.UseProgram(s.facing_program);
  gl.BindVertexArray(s.empty_vertex_array);
  gl.DrawArrays(GL_TRIANGLES, 0, 3);
  gl.BindVertexArray(0);
  gl.UseProgram(0);
  gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGl(s, "set-up facing reset");
}

// After the draw into `t`: resolves the colour into the bound single-sample FBO, reads it,
// then every sample's id and depth, and fills frame's multisample planes and resolve.
void readBackMultisample(Session& s, const Scene& scene, MultisampleTargets& t, Frame& frame) {
  const gl::Functions& gl = s.gl;
  const int w = scene.width;
  const int h = scene.height;
  const int samples = scene.state.samples;
  const GLuint single = s.framebuffer.framebuffer;
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t.framebuffer);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, single);
  const GLenum color_only[2] = {GL_COLOR_ATTACHMENT0, GL_NONE};
  gl.DrawBuffers(2, color_only);  // a float blit into the R32UI attachment is an error
  gl.BlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  checkGl(s, "multisample resolve");
  gl.BindFramebuffer(GL_FRAMEBUFFER, single);
  readBack(s, scene, frame);  // the resolved colour (id and depth are replaced below)

  const GLuint program = sampleProgram(s);
  const GLenum ids_only[2] = {GL_NONE, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, ids_only);
  gl.Disable(GL_DEPTH_TEST);
  gl.Disable(GL_MULTISAMPLE);
  gl.Disablei(GL_BLEND, 0);
  gl.Disable(GL_CULL_FACE);
  gl.UseProgram(program);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t.textures[0]);
  gl.ActiveTexture(GL_TEXTURE1);
  gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t.textures[1]);
  gl.Uniform1i(gl.GetUniformLocation(program, "u_ids"), 0);
  gl.Uniform1i(gl.GetUniformLocation(program, "u_depth"), 1);
  const int bits = depthBits(scene.state.depth_format);
  const double steps = bits == 0 ? 0.0 : std::ldexp(1.0, bits) - 1.0;
  gl.Uniform1f(gl.GetUniformLocation(program, "u_depth_scale"), static_cast<float>(steps));
  gl.BindVertexArray(s.empty_vertex_array);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
  const std::size_t n = static_cast<std::size_t>(w) * h;
  frame.samples = samples;
  frame.sample_id.resize(n * samples);
  frame.sample_depth.resize(n * samples);
  std::vector<std::uint32_t> raw(n);
  for (int k = 0; k < samples; ++k) {
    gl.Uniform1i(gl.GetUniformLocation(program, "u_sample"), k);
    for (int what = 0; what < 2; ++what) {
      gl.Uniform1i(gl.GetUniformLocation(program, "u_what"), what);
      gl.DrawArrays(GL_TRIANGLES, 0, 3);
      readRows(gl, false, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, raw.data(),
               static_cast<std::size_t>(w) * 4);
      const std::size_t at = static_cast<std::size_t>(k) * n;
      for (std::size_t i = 0; i < n; ++i) {
        if (what == 0) {
          frame.sample_id[at + i] = raw[i];
        } else {
          frame.sample_depth[at + i] =
              bits == 0 ? std::bit_cast<float>(raw[i]) : static_cast<float>(raw[i] / steps);
        }
      }
    }
  }
  gl.BindVertexArray(0);
  gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, 0);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, 0);
  gl.UseProgram(0);
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, both);
  resolveSampleOwners(frame);
}

// Lights cost 5 vec4 slots each in the worst packing; the rest of the uniforms fit in 16.
constexpr int kSlotsPerLight = 5;
constexpr int kOtherSlots = 16;

int lightArraySize(const gl::Functions& gl, std::size_t lights) {
  const int components = std::min(glInteger(gl, GL_MAX_VERTEX_UNIFORM_COMPONENTS),
                                  glInteger(gl, GL_MAX_FRAGMENT_UNIFORM_COMPONENTS));
  const int max_lights = (components / 4 - kOtherSlots) / kSlotsPerLight;
  if (lights > static_cast<std::size_t>(max_lights)) {
    throw BackendError(fmt::format(
        "the scene has {} lights; this driver's uniform limits ({} components) allow at most {}",
        lights, components, max_lights));
  }
  // Power-of-two array sizes (at least 8) keep the number of distinct programs small.
  int size = 8;
  while (static_cast<std::size_t>(size) < lights) size *= 2;
  return std::min(size, max_lights);
}

// The faults of this render: the in-process hooks, else RASTERCHECK_GL_FAULT. A faulted
// process says so once on stderr, so nobody mistakes its frames for real ones.
gl::testing::Faults activeFaults() {
  gl::testing::Faults faults = gl::testing::hooks().faults;
  if (!faults.any()) {
    const char* env = std::getenv(gl::testing::kFaultVariable);
    if (env != nullptr) faults = gl::testing::parseFaults(env);
  }
  static bool warned = false;
  if (faults.any() && !warned) {
    warned = true;
    std::fprintf(
        stderr,
        "rastercheck: warning: GL fault injected (%s): test-only, frames are wrong on purpose\n",
        faults.describe().c_str());
  }
  return faults;
}

// The test-only hang and crash faults: what a driver stuck in a fence or faulting in its
// rasterizer looks like from outside (gl_testing.h).
void injectStall(const gl::testing::Faults& faults, const std::string& fixture) {
  if (faults.crashes(fixture)) {
    std::signal(SIGSEGV, SIG_DFL);  // a sanitizer's handler would turn it into an exit code
    std::raise(SIGSEGV);
  }
  bool hang = faults.hangs(fixture);
  if (!hang && faults.hangsOnce(fixture)) {
    // The first render in this temporary folder creates the marker and hangs; the others
    // find it. O_EXCL makes "first" hold across processes.
    std::string slug = fixture;
    for (char& c : slug)
      if (std::isalnum(static_cast<unsigned char>(c)) == 0) c = '_';
    const std::filesystem::path marker =
        std::filesystem::temp_directory_path() / ("rastercheck-hang-once-" + slug);
    const int fd = ::open(marker.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd >= 0) {
      ::close(fd);
      hang = true;
    }
  }
  if (hang) {
    // Said in the render's own output: a `run` worker keeps what it printed during the
    // render it was killed in, and the once-per-process fault warning may belong to an
    // earlier render of the same worker.
    std::fprintf(stderr, "rastercheck: test fault: the draw of %s hangs\n", fixture.c_str());
    std::fflush(nullptr);
    for (;;) ::pause();
  }
}

// The test-only flaky fault: one pixel, chosen by the operating system's entropy (so no
// two renders agree) among those whose 3x3 neighbourhood shows one primitive (drawn ones
// first: away from every edge, where no allowance forgives it), loses its primitive (a
// drawn pixel shows the background; a background pixel an id no scene has: neither is
// forgiven by a depth tie) and has red 64..191 8-bit units off.
void injectFlake(const gl::testing::Faults& faults, const std::string& fixture, Frame& frame) {
  if (!faults.flakes(fixture) || frame.color.empty()) return;
  std::random_device entropy;
  const int w = frame.width, h = frame.height;
  std::vector<std::size_t> drawn, background;
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const std::size_t i = frame.index(x, y);
      bool uniform = true;
      for (int dy = -1; dy <= 1 && uniform; ++dy)
        for (int dx = -1; dx <= 1 && uniform; ++dx)
          uniform = frame.id[frame.index(x + dx, y + dy)] == frame.id[i];
      if (uniform) (frame.id[i] != 0 ? drawn : background).push_back(i);
    }
  const std::vector<std::size_t>& from = drawn.empty() ? background : drawn;
  const std::size_t pick =
      from.empty() ? entropy() % frame.pixelCount() : from[entropy() % from.size()];
  frame.id[pick] = frame.id[pick] != 0 ? 0u : 0x7fffffffu;
  const auto units = static_cast<float>(64 + entropy() % 128);
  float& red = frame.color[4 * pick];
  red = red > 0.5f ? red - units / 255.0f : red + units / 255.0f;
}

// ---- multi-pass scenes ---------------------------------------------------------------
// The passes before the frame pass draw into framebuffers of their own, each target's
// contents in a texture (colour, or depth with its compare state set per lookup) that the
// later passes sample; their frames are read back for `render --all-passes`.
struct PassTargets {
  const gl::Functions& gl;
  std::map<std::string, GLuint> color;  // colour targets' textures, by name
  std::map<std::string, GLuint> depth;  // depth targets' textures, by name
  std::vector<GLuint> textures;
  std::vector<GLuint> renderbuffers;
  std::vector<GLuint> framebuffers;

  explicit PassTargets(const gl::Functions& functions) : gl(functions) {}
  PassTargets(const PassTargets&) = delete;
  PassTargets& operator=(const PassTargets&) = delete;
  ~PassTargets() {
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!framebuffers.empty())
      gl.DeleteFramebuffers(static_cast<GLsizei>(framebuffers.size()), framebuffers.data());
    if (!renderbuffers.empty())
      gl.DeleteRenderbuffers(static_cast<GLsizei>(renderbuffers.size()), renderbuffers.data());
    if (!textures.empty())
      gl.DeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
    gl.GetError();
  }

  GLuint texture(GLenum internal, GLenum format, GLenum type, int w, int h) {
    GLuint t = 0;
    gl.GenTextures(1, &t);
    textures.push_back(t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.TexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal), w, h, 0, format, type, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    return t;
  }
  GLuint renderbuffer(GLenum internal, int w, int h) {
    GLuint r = 0;
    gl.GenRenderbuffers(1, &r);
    renderbuffers.push_back(r);
    gl.BindRenderbuffer(GL_RENDERBUFFER, r);
    gl.RenderbufferStorage(GL_RENDERBUFFER, internal, w, h);
    return r;
  }
};

bool hasShadowLookups(const Scene& scene) {
  return std::any_of(scene.materials.begin(), scene.materials.end(),
                     [](const Material& m) { return m.shadow.has_value(); });
}

// The shadow lookups of `pass_scene`'s materials (multi-pass `scene`): empty when none.
std::vector<MaterialShadow> materialShadows(const Scene& scene, const Scene& pass_scene,
                                            const PassTargets& targets,
                                            const gl::testing::Faults& faults) {
  std::vector<MaterialShadow> out;
  if (!hasShadowLookups(pass_scene)) return out;
  out.resize(pass_scene.materials.size());
  for (std::size_t m = 0; m < pass_scene.materials.size(); ++m) {
    const std::optional<ShadowLookup>& lookup = pass_scene.materials[m].shadow;
    if (!lookup) continue;
    const auto it = targets.depth.find(lookup->map);
    if (it == targets.depth.end()) continue;
    MaterialShadow& sh = out[m];
    sh.texture = it->second;
    sh.matrix = glm::mat4(shadowMatrix(scene, lookup->map));
    sh.compare = static_cast<GLint>(glCompare(
        faults.shadow_compare_inverted ? invertedFunc(lookup->compare) : lookup->compare));
    sh.filter = lookup->filter == TextureFilter::Linear ? GL_LINEAR : GL_NEAREST;
    sh.bias = faults.shadow_bias_dropped ? 0.0f : static_cast<GLfloat>(lookup->bias);
    for (const Light& l : pass_scene.lights) sh.shadowed.push_back(l.shadow_map == lookup->map);
  }
  return out;
}

// Draws pass k (before the frame pass) of `scene` into its target and reads it back. The
// test-only faults are the frame pass's: these passes draw without them.
Frame drawTargetPass(Session& s, const Program& program, const Scene& scene, std::size_t k,
                     PassTargets& targets, int max_texture_size, bool read_back) {
  const gl::Functions& gl = s.gl;
  const Scene ps = passScene(scene, k);
  const RenderTarget& target = *findTarget(scene, scene.passes[k].target);
  if (target.width > max_texture_size || target.height > max_texture_size)
    throw BackendError(fmt::format("target {} is {}x{}, GL_MAX_TEXTURE_SIZE is {}", target.name,
                                   target.width, target.height, max_texture_size));
  const int w = ps.width;
  const int h = ps.height;
  GLuint fb = 0;
  gl.GenFramebuffers(1, &fb);
  targets.framebuffers.push_back(fb);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fb);
  const AttachmentFormat color = colorFormat(ps.state.color_format);
  const AttachmentFormat depth = depthFormat(ps.state.depth_format);
  if (target.depth()) {
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                               targets.renderbuffer(color.internal, w, h));
    const GLuint t = targets.texture(depth.internal, GL_DEPTH_COMPONENT, GL_FLOAT, w, h);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, t, 0);
    targets.depth[target.name] = t;
  } else {
    const bool rgba8 = ps.state.color_format == ColorFormat::RGBA8;
    const GLuint t =
        targets.texture(color.internal, GL_RGBA, rgba8 ? GL_UNSIGNED_BYTE : GL_FLOAT, w, h);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t, 0);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                               targets.renderbuffer(depth.internal, w, h));
    targets.color[target.name] = t;
  }
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER,
                             targets.renderbuffer(GL_R32UI, w, h));
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    const std::string what =
        fmt::format("target {} ({} {}x{}): framebuffer incomplete: {}", target.name,
                    toString(target.format), w, h, framebufferStatusName(status));
    if (status == GL_FRAMEBUFFER_UNSUPPORTED) throw NotSupportedError(what);
    throw BackendError(what);
  }
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, draw_buffers);
  checkGl(s, "target framebuffer setup");

  const gl::testing::Faults none;
  const std::vector<DrawPass> passes = drawPasses(ps);
  const gl::VertexData data = gl::buildVertexData(ps, passes, none);
  RenderObjects objects(gl);
  uploadVertices(objects, data);
  const std::vector<GLuint> textures =
      uploadTextures(objects, ps, max_texture_size, none, targets.color);
  setSceneUniforms(gl, program, ps, none);
  setFixedState(gl, ps);
  clearFramebuffer(gl, ps);
  drawPassesGl(gl, program, ps, data, textures, materialShadows(scene, ps, targets, none), none,
               FallbackFlush(s, program));
  resetPassState(gl);
  checkGl(s, fmt::format("pass {} (target {})", k, target.name).c_str());
  Frame frame;
  if (!read_back) return frame;
  readBack(s, ps, frame);
  checkGl(s, "target readback");
  frame.meta["pass"] = {{"index", k}, {"target", target.name}, {"format", toString(target.format)}};
  frame.drawn = drawFacts(ps);
  return frame;
}

Frame renderLocked(const Scene& multi, const GlSpec& spec, bool want_pass_frames) {
  // A multi-pass scene draws its targets first, then its frame pass (`scene` below).
  validateForRendering(multi);
  const bool multipass = !multi.passes.empty();
  const Scene frame_scene = multipass ? passScene(multi, multi.passes.size() - 1) : Scene{};
  const Scene& scene = multipass ? frame_scene : multi;

  const gl::testing::Faults faults = activeFaults();  // bad RASTERCHECK_GL_FAULT: exit 2
  const std::vector<DrawPass> passes = drawPasses(scene);
  auto start = Clock::now();
  Session& s = acquireSession(spec);
  s.fallbacks_this_render = 0;
  struct Release {
    Session& s;
    ~Release() { s.context->release(); }
  } release{s};
  const gl::Functions& gl = s.gl;
  s.debug_errors.clear();
  while (gl.GetError() != GL_NO_ERROR) {
  }
  const double context_ms = msSince(start);

  // Compiling is the driver's work and happens once per process and program; it is
  // timed apart from the upload (the harness's own work).
  start = Clock::now();
  const Program& program =
      programFor(s, lightArraySize(gl, scene.lights.size()), faults, hasShadowLookups(scene));
  checkGl(s, "shader compilation");
  const double compile_ms = msSince(start);

  // The FBO: allocated by the driver on the first render of a size and format, reused
  // after that.
  start = Clock::now();
  double cpu_start = threadCpuMs();
  const int max_rb = glInteger(gl, GL_MAX_RENDERBUFFER_SIZE);
  GLint max_viewport[2] = {0, 0};
  gl.GetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
  if (scene.width > std::min(max_rb, max_viewport[0]) ||
      scene.height > std::min(max_rb, max_viewport[1])) {
    throw BackendError(
        fmt::format("image {}x{} exceeds the driver's limits (GL_MAX_RENDERBUFFER_SIZE {}, "
                    "GL_MAX_VIEWPORT_DIMS {}x{})",
                    scene.width, scene.height, max_rb, max_viewport[0], max_viewport[1]));
  }
  const int max_samples = glInteger(gl, GL_MAX_SAMPLES);
  const int samples = scene.state.samples;
  if (samples > 1) {
    const int usable = maxUsableSamples(gl);
    if (usable < samples)
      throw NotSupportedError(fmt::format(
          "{} samples per pixel: this driver gives at most {} (GL_MAX_SAMPLES {}; colour, depth "
          "and integer texture limits included)",
          samples, usable, max_samples));
  }
  s.render_unfinished = true;  // until the frame is read back
  if (s.driver == "softpipe" && std::string_view(s.context_use) == "reused") resetSetupFacing(s);
  PassTargets targets(gl);
  std::vector<Frame> pass_frames;
  double passes_ms = 0.0;
  if (multipass) {
    const auto passes_start = Clock::now();
    for (std::size_t k = 0; k + 1 < multi.passes.size(); ++k) {
      Frame pass = drawTargetPass(s, program, multi, k, targets, glInteger(gl, GL_MAX_TEXTURE_SIZE),
                                  want_pass_frames);
      if (want_pass_frames) pass_frames.push_back(std::move(pass));
    }
    passes_ms = msSince(passes_start);
  }
  bindFramebuffer(s, scene);
  checkGl(s, "framebuffer setup");
  MultisampleTargets ms(gl);
  nlohmann::json multisample;
  if (samples > 1) {
    createMultisampleTargets(s, scene, ms);
    const int given = glInteger(gl, GL_SAMPLES);
    if (given != samples)
      throw NotSupportedError(
          fmt::format("{} samples per pixel: the driver allocates {} for that request (GL_SAMPLES)",
                      samples, given));
    nlohmann::json positions = nlohmann::json::array();
    for (int k = 0; k < samples; ++k) {
      GLfloat p[2] = {0.0f, 0.0f};
      gl.GetMultisamplefv(GL_SAMPLE_POSITION, static_cast<GLuint>(k), p);
      positions.push_back({static_cast<double>(p[0]), static_cast<double>(p[1])});
    }
    checkGl(s, "sample positions");
    multisample = {{"samples", samples},
                   {"positions", positions},
                   {"max_samples", max_samples},
                   {"usable_samples", maxUsableSamples(gl)}};
  }
  const double framebuffer_ms = msSince(start);
  const double framebuffer_cpu_ms = threadCpuMs() - cpu_start;

  start = Clock::now();
  cpu_start = threadCpuMs();
  gl::VertexData data = gl::buildVertexData(scene, passes, faults);
  // Scenes with polygon offset measure the driver's r first (single-sample frames).
  const bool probe_offset =
      samples == 1 && std::any_of(passes.begin(), passes.end(), [](const DrawPass& p) {
        return p.ops.polygon_offset.has_value();
      });
  const auto probe_first = static_cast<GLint>(data.vertices.size());
  if (probe_offset) appendOffsetProbe(data);
  if (data.vertices.size() > static_cast<std::size_t>(INT32_MAX)) {
    throw BackendError(
        fmt::format("{} vertices exceed what one glDrawArrays can address", data.vertices.size()));
  }
  RenderObjects objects(gl);
  uploadVertices(objects, data);
  const std::vector<GLuint> textures =
      uploadTextures(objects, scene, glInteger(gl, GL_MAX_TEXTURE_SIZE), faults, targets.color);
  const std::vector<MaterialShadow> shadows = materialShadows(multi, scene, targets, faults);
  setSceneUniforms(gl, program, scene, faults);
  if (gl::testing::hooks().gl_error_after_upload) gl.Enable(0xFFFFu);  // not a capability
  checkGl(s, "upload");
  const double upload_ms = msSince(start);
  const double upload_cpu_ms = threadCpuMs() - cpu_start;

  start = Clock::now();
  setFixedState(gl, scene);
  if (samples > 1) gl.Enable(GL_MULTISAMPLE);  // multisample rasterization into `ms`
  std::optional<double> offset_r;
  if (probe_offset) {
    clearFramebuffer(gl, scene);
    offset_r = measureOffsetR(gl, program, scene, probe_first, FallbackFlush(s, program));
  }
  clearFramebuffer(gl, scene);
  const FallbackFlush fallback(s, program);
  drawPassesGl(gl, program, scene, data, textures, shadows, faults, fallback);
  // A render that drew nothing still validates its program's samplers at the read-back (a
  // new context's Mesa creates the fallbacks there): count them as created. A flush here,
  // after the last draw, changes no pixel.
  fallback.beforeDraw();
  resetPassState(gl);
  gl.Finish();
  injectStall(faults, scene.name);
  checkGl(s, "draw");
  const double draw_ms = msSince(start);

  start = Clock::now();
  cpu_start = threadCpuMs();
  Frame frame;
  if (samples > 1) {
    readBackMultisample(s, scene, ms, frame);
  } else {
    readBack(s, scene, frame);
  }
  checkGl(s, "readback");
  s.render_unfinished = false;
  injectFlake(faults, scene.name, frame);
  const double readback_ms = msSince(start);
  const double readback_cpu_ms = threadCpuMs() - cpu_start;

  nlohmann::json& m = frame.meta;
  m["renderer"] = s.renderer;
  m["gl_vendor"] = s.vendor;
  m["gl_renderer"] = s.renderer;
  m["gl_version"] = s.version;
  m["glsl_version"] = s.glsl_version;
  m["subpixel_bits"] = s.subpixel_bits;  // what the comparator's snap band uses
  if (offset_r) m["polygon_offset_r"] = *offset_r;
  m["gl_subpixel_bits"] = s.gl_subpixel_bits;
  m["subpixel_bits_source"] = s.subpixel_source;
  m["platform"] = s.context->platform();
  m["context"] = s.context_use;
  m["program"] = s.program_use;
  m["program_binary"] = s.program_binary;
  m["driver"] = s.driver;
  m["stack"] = s.stack;
  m["mesa"] = gl::toJson(s.mesa, s.spec, s.mesa_version);
  // llvmpipe's (and lavapipe's) rasterizer threads as this process was started with them:
  // `run`'s workers choose it (app/worker_pool.cpp); null: the driver's default, one a core.
  const char* lp_threads = std::getenv("LP_NUM_THREADS");
  m["lp_num_threads"] = lp_threads != nullptr ? nlohmann::json(lp_threads) : nlohmann::json();
  if (s.zink) {
    m["vulkan"] = s.vulkan ? gl::toJson(*s.vulkan) : nlohmann::json{{"error", s.vulkan_error}};
    m["vulkan"]["query_ms"] = s.vulkan_query_ms;
  }
  m["max_samples"] = max_samples;  // GL_MAX_SAMPLES
  if (samples > 1) m["multisample"] = multisample;
  m["skipped_triangles"] = data.skipped_triangles;
  if (faults.any()) m["fault_injected"] = faults.describe();
  m["timing_ms"] = {
      {"context", context_ms}, {"compile", compile_ms}, {"framebuffer", framebuffer_ms},
      {"upload", upload_ms},   {"draw", draw_ms},       {"readback", readback_ms}};
  m["timing_cpu_ms"] = {{"framebuffer", framebuffer_cpu_ms},
                        {"upload", upload_cpu_ms},
                        {"readback", readback_cpu_ms}};
  if (multipass) m["timing_ms"]["passes"] = passes_ms;
  frame.passes = std::move(pass_frames);
  frame.drawn = drawFacts(scene);  // what a comparison of this frame needs
  return frame;
}

}  // namespace

Frame renderGl(const Scene& scene, const GlSpec& spec, bool pass_frames) {
  const std::string name = scene.name.empty() ? "(unnamed scene)" : scene.name;
  try {
    const std::lock_guard lock(g_mutex);
    return renderLocked(scene, spec, pass_frames);
  } catch (const NotSupportedError& e) {
    throw NotSupportedError(
        fmt::format("not supported: {}: {}: {}", name, toString(spec), e.what()));
  } catch (const BackendError& e) {
    throw BackendError(fmt::format("{}: {}: {}", name, toString(spec), e.what()));
  } catch (const std::bad_alloc&) {
    throw BackendError(fmt::format("{}: {}: out of memory for a {}x{} frame", name, toString(spec),
                                   scene.width, scene.height));
  }
}

}  // namespace rc
