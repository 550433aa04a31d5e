// OSMesa context provider: see context.h. Compiled to a stub that always fails when
// the build found no OSMesa (Mesa 25.1 removed it).
#include "gl_backend/context.h"

#include "fixtures/errors.h"

#ifdef RC_HAVE_OSMESA
#include <GL/osmesa.h>

#include <array>
#endif

namespace rc::gl {

#ifdef RC_HAVE_OSMESA
namespace {

ProcAddress osmesaLoader(const char* name) { return OSMesaGetProcAddress(name); }

class OsMesaContext final : public Context {
 public:
  OsMesaContext() {
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_STENCIL_BITS,
                           0,
                           OSMESA_ACCUM_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           3,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           3,
                           0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (context_ == nullptr)
      throw BackendError("OSMesaCreateContextAttribs (OpenGL 3.3 core) failed");
  }
  ~OsMesaContext() override { OSMesaDestroyContext(context_); }

  void makeCurrent() override {
    // OSMesa needs a colour buffer to become current; everything is drawn into the
    // backend's FBO, so a 1x1 one is enough.
    if (OSMesaMakeCurrent(context_, pixel_.data(), GL_UNSIGNED_BYTE, 1, 1) == 0)
      throw BackendError("OSMesaMakeCurrent failed");
  }
  // OSMesa cannot unbind a context (OSMesaMakeCurrent(NULL...) is not portable across
  // versions); the context simply stays current on this thread.
  void release() override {}

  ProcLoader loader() const override { return &osmesaLoader; }
  const char* platform() const override { return "osmesa"; }

 private:
  OSMesaContext context_ = nullptr;
  std::array<unsigned char, 4> pixel_{};
};

}  // namespace

std::unique_ptr<Context> createOsMesaContext() { return std::make_unique<OsMesaContext>(); }

#else

std::unique_ptr<Context> createOsMesaContext() {
  throw BackendError("this build has no OSMesa (libosmesa6-dev was not found at configure time)");
}

#endif

}  // namespace rc::gl
