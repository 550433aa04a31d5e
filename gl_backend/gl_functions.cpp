// Loading the GL function table: see gl_functions.h.
#include "gl_backend/gl_functions.h"

#include <cstring>
#include <string>

#include "fixtures/errors.h"

namespace rc::gl {

void Functions::load(ProcLoader loader) {
// The arguments are a type and a member name, which cannot be parenthesized.
// NOLINTBEGIN(bugprone-macro-parentheses)
#define RC_GL_LOAD(type, name)                                                       \
  name = reinterpret_cast<type>(loader("gl" #name));                                 \
  if (name == nullptr) {                                                             \
    throw BackendError("the GL provider does not export gl" #name " (GL 3.3 core)"); \
  }
  // NOLINTEND(bugprone-macro-parentheses)
  RC_GL_CORE_FUNCTIONS(RC_GL_LOAD)
#undef RC_GL_LOAD

  // KHR_debug is core in 4.3 and an extension below (softpipe exposes 3.3 core).
  GLint count = 0;
  GetIntegerv(GL_NUM_EXTENSIONS, &count);
  bool khr_debug = false;
  bool program_binary = false;
  pack_invert = false;
  for (GLint i = 0; i < count; ++i) {
    const auto* ext = reinterpret_cast<const char*>(GetStringi(GL_EXTENSIONS, i));
    if (ext == nullptr) continue;
    khr_debug = khr_debug || std::strcmp(ext, "GL_KHR_debug") == 0;
    pack_invert = pack_invert || std::strcmp(ext, "GL_MESA_pack_invert") == 0;
    program_binary = program_binary || std::strcmp(ext, "GL_ARB_get_program_binary") == 0;
  }
  // Program binaries: core in 4.1, else the extension; usable only with a format to use.
  GLint major = 0;
  GLint minor = 0;
  GetIntegerv(GL_MAJOR_VERSION, &major);
  GetIntegerv(GL_MINOR_VERSION, &minor);
  GLint formats = 0;
  if (program_binary || major * 10 + minor >= 41)
    GetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
  auto get = reinterpret_cast<PFNGLGETPROGRAMBINARYPROC>(loader("glGetProgramBinary"));
  auto put = reinterpret_cast<PFNGLPROGRAMBINARYPROC>(loader("glProgramBinary"));
  const bool binaries = formats > 0 && get != nullptr && put != nullptr;
  GetProgramBinary = binaries ? get : nullptr;
  ProgramBinary = binaries ? put : nullptr;
  DebugMessageCallback =
      khr_debug ? reinterpret_cast<PFNGLDEBUGMESSAGECALLBACKPROC>(loader("glDebugMessageCallback"))
                : nullptr;
}

}  // namespace rc::gl
