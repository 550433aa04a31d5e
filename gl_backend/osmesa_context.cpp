// OSMesa context provider: see context.h. Compiled to a stub that always fails when
// the build found no OSMesa (Mesa 25.1 removed it). libOSMesa is opened on first use
// rather than linked: it pulls in the gallium drivers and LLVM, whose relocations would
// otherwise cost every rastercheck process (reference renders, compare) tens of ms.
#include "gl_backend/context.h"

#include "fixtures/errors.h"

#ifdef RC_HAVE_OSMESA
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <array>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>
#endif

namespace rc::gl {

#ifdef RC_HAVE_OSMESA
namespace {

// The four OSMesa entry points the provider uses, from the library found at configure
// time (RC_OSMESA_SONAME). RTLD_LOCAL keeps its GL symbols out of the global scope.
struct OsMesaApi {
  decltype(&OSMesaCreateContextAttribs) create_context = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaGetProcAddress) get_proc_address = nullptr;
};

// `mesa_dir` counts on the first call only: one OSMesa per process.
const OsMesaApi& osmesa(const std::string& mesa_dir = "") {
  static OsMesaApi api;
  static std::string error;
  static std::once_flag once;
  std::call_once(once, [&] {
    // From another Mesa's folder by its path: the dynamic loader's search (and
    // LD_LIBRARY_PATH) would find the system's library first when run in-process.
    const std::string file =
        mesa_dir.empty() ? std::string(RC_OSMESA_SONAME) : mesa_dir + "/" RC_OSMESA_SONAME;
    void* lib = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (lib == nullptr) {
      const char* why = ::dlerror();
      error = "cannot load " + file + ": " + (why ? why : "unknown error");
      return;
    }
    auto symbol = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(::dlsym(lib, name));
      if (fn == nullptr && error.empty()) error = file + " does not export " + name;
    };
    symbol(api.create_context, "OSMesaCreateContextAttribs");
    symbol(api.destroy_context, "OSMesaDestroyContext");
    symbol(api.make_current, "OSMesaMakeCurrent");
    symbol(api.get_proc_address, "OSMesaGetProcAddress");
  });
  if (!error.empty()) throw BackendError(error);
  return api;
}

ProcAddress osmesaLoader(const char* name) { return osmesa().get_proc_address(name); }

class OsMesaContext final : public Context {
 public:
  explicit OsMesaContext(const std::string& mesa_dir) {
    osmesa(mesa_dir);  // loads the library on the process's first context
    createContext();
  }
  ~OsMesaContext() override {
    osmesa().destroy_context(context_);
    for (OSMesaContext old : abandoned_) osmesa().destroy_context(old);
  }

  void makeCurrent() override {
    // OSMesa needs a colour buffer to become current; everything is drawn into the
    // backend's FBO, so a 1x1 one is enough.
    if (osmesa().make_current(context_, pixel_.data(), GL_UNSIGNED_BYTE, 1, 1) == 0)
      throw BackendError("OSMesaMakeCurrent failed");
  }
  // OSMesa cannot unbind a context (OSMesaMakeCurrent(NULL...) is not portable across
  // versions); the context simply stays current on this thread.
  void release() override {}

  void renew() override {
    osmesa().destroy_context(context_);
    context_ = nullptr;
    createContext();
  }

  void abandon() override {
    abandoned_.push_back(context_);
    context_ = nullptr;
    createContext();
  }

  ProcLoader loader() const override { return &osmesaLoader; }
  const char* platform() const override { return "osmesa"; }

 private:
  void createContext() {
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
    context_ = osmesa().create_context(attribs, nullptr);
    if (context_ == nullptr)
      throw BackendError("OSMesaCreateContextAttribs (OpenGL 3.3 core) failed");
  }

  OSMesaContext context_ = nullptr;
  std::vector<OSMesaContext> abandoned_;  // abandon(): destroyed only with this object
  std::array<unsigned char, 4> pixel_{};
};

}  // namespace

std::unique_ptr<Context> createOsMesaContext(const std::string& mesa_dir) {
  return std::make_unique<OsMesaContext>(mesa_dir);
}

#else

std::unique_ptr<Context> createOsMesaContext(const std::string& /*mesa_dir*/) {
  throw BackendError("this build has no OSMesa (libosmesa6-dev was not found at configure time)");
}

#endif

}  // namespace rc::gl
