// The GL entry points the backend calls, loaded through the context provider's
// getProcAddress into one table. Nothing links libGL/libOpenGL, so the symbols of
// libOSMesa and of the EGL vendor library can never clash.
#pragma once

#include <GL/glcorearb.h>

#include "gl_backend/context.h"

// From the GL_MESA_pack_invert specification (not in glcorearb.h).
#ifndef GL_PACK_INVERT_MESA
#define GL_PACK_INVERT_MESA 0x8758
#endif

namespace rc::gl {

// X(type, name): the member `name` holds "gl" #name. Only GL 3.3 core functions, plus
// KHR_debug's callback which is loaded when the extension is present.
#define RC_GL_CORE_FUNCTIONS(X)                                                        \
  X(PFNGLGETSTRINGPROC, GetString)                                                     \
  X(PFNGLGETSTRINGIPROC, GetStringi)                                                   \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                 \
  X(PFNGLGETERRORPROC, GetError)                                                       \
  X(PFNGLENABLEPROC, Enable)                                                           \
  X(PFNGLDISABLEPROC, Disable)                                                         \
  X(PFNGLENABLEIPROC, Enablei)                                                         \
  X(PFNGLDISABLEIPROC, Disablei)                                                       \
  X(PFNGLVIEWPORTPROC, Viewport)                                                       \
  X(PFNGLDEPTHRANGEPROC, DepthRange)                                                   \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                                     \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                                     \
  X(PFNGLCOLORMASKPROC, ColorMask)                                                     \
  X(PFNGLBLENDFUNCPROC, BlendFunc)                                                     \
  X(PFNGLBLENDEQUATIONPROC, BlendEquation)                                             \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)                                     \
  X(PFNGLBLENDEQUATIONSEPARATEPROC, BlendEquationSeparate)                             \
  X(PFNGLBLENDCOLORPROC, BlendColor)                                                   \
  X(PFNGLCOLORMASKIPROC, ColorMaski)                                                   \
  X(PFNGLSTENCILFUNCSEPARATEPROC, StencilFuncSeparate)                                 \
  X(PFNGLSTENCILOPSEPARATEPROC, StencilOpSeparate)                                     \
  X(PFNGLSTENCILMASKSEPARATEPROC, StencilMaskSeparate)                                 \
  X(PFNGLSTENCILMASKPROC, StencilMask)                                                 \
  X(PFNGLSCISSORPROC, Scissor)                                                         \
  X(PFNGLPOLYGONOFFSETPROC, PolygonOffset)                                             \
  X(PFNGLCLEARBUFFERIVPROC, ClearBufferiv)                                             \
  X(PFNGLFRONTFACEPROC, FrontFace)                                                     \
  X(PFNGLCULLFACEPROC, CullFace)                                                       \
  X(PFNGLPOLYGONMODEPROC, PolygonMode)                                                 \
  X(PFNGLLINEWIDTHPROC, LineWidth)                                                     \
  X(PFNGLPOINTSIZEPROC, PointSize)                                                     \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                             \
  X(PFNGLCLEARBUFFERUIVPROC, ClearBufferuiv)                                           \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                                 \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                                   \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                                   \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                 \
  X(PFNGLFINISHPROC, Finish)                                                           \
  X(PFNGLFLUSHPROC, Flush)                                                             \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                         \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                         \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                   \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                         \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                           \
  X(PFNGLGETFRAMEBUFFERATTACHMENTPARAMETERIVPROC, GetFramebufferAttachmentParameteriv) \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                                       \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                       \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                                 \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                                 \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                                   \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                                   \
  X(PFNGLBUFFERDATAPROC, BufferData)                                                   \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                             \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                         \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                         \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                   \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                 \
  X(PFNGLVERTEXATTRIBIPOINTERPROC, VertexAttribIPointer)                               \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                         \
  X(PFNGLCREATESHADERPROC, CreateShader)                                               \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                               \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                             \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                 \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                       \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                               \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                             \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                               \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                 \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                               \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                     \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                             \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                                   \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                   \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                                     \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                                     \
  X(PFNGLUNIFORM1IVPROC, Uniform1iv)                                                   \
  X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                                   \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                                   \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                       \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                                 \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                                 \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                             \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                                   \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                             \
  X(PFNGLTEXPARAMETERFPROC, TexParameterf)                                             \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                           \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                                   \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                                         \
  X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample)           \
  X(PFNGLTEXIMAGE2DMULTISAMPLEPROC, TexImage2DMultisample)                             \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                               \
  X(PFNGLGETMULTISAMPLEFVPROC, GetMultisamplefv)

struct Functions {
#define RC_GL_DECLARE(type, name) type name = nullptr;
  RC_GL_CORE_FUNCTIONS(RC_GL_DECLARE)
#undef RC_GL_DECLARE
  PFNGLDEBUGMESSAGECALLBACKPROC DebugMessageCallback = nullptr;  // null without KHR_debug
  // ARB_get_program_binary (core in 4.1): null without it, or when the driver offers no
  // binary format (GL_NUM_PROGRAM_BINARY_FORMATS 0, e.g. Mesa without its shader cache).
  PFNGLGETPROGRAMBINARYPROC GetProgramBinary = nullptr;
  PFNGLPROGRAMBINARYPROC ProgramBinary = nullptr;
  // GL_MESA_pack_invert: glReadPixels can return rows top first (GL_PACK_INVERT_MESA).
  bool pack_invert = false;

  // Loads every entry point; throws BackendError naming the first one that is missing.
  // Must be called with the context current (some providers only resolve then).
  void load(ProcLoader loader);
};

}  // namespace rc::gl
