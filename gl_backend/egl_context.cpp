// EGL context providers (surfaceless platform and EGL devices): see context.h.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "fixtures/errors.h"
#include "gl_backend/context.h"

namespace rc::gl {
namespace {

const char* eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE:
      return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP:
      return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW:
      return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST:
      return "EGL_CONTEXT_LOST";
    default:
      return "unknown EGL error";
  }
}

[[noreturn]] void failEgl(std::string_view what) {
  const EGLint error = eglGetError();
  throw BackendError(fmt::format("{} failed ({})", what, eglErrorName(error)));
}

// Extension strings are space-separated names; a plain substring test would match
// prefixes (EGL_EXT_device_drm vs EGL_EXT_device_drm_render_node).
bool hasExtension(const char* list, std::string_view name) {
  if (list == nullptr) return false;
  std::string_view rest(list);
  while (!rest.empty()) {
    const std::size_t end = rest.find(' ');
    if (rest.substr(0, end) == name) return true;
    if (end == std::string_view::npos) break;
    rest.remove_prefix(end + 1);
  }
  return false;
}

template <typename Fn>
Fn eglProc(const char* name) {
  auto fn = reinterpret_cast<Fn>(eglGetProcAddress(name));
  if (fn == nullptr) throw BackendError(fmt::format("EGL does not export {}", name));
  return fn;
}

ProcAddress eglLoader(const char* name) { return eglGetProcAddress(name); }

class EglContext final : public Context {
 public:
  EglContext(EGLDisplay display, const char* platform) : display_(display), platform_(platform) {
    EGLint major = 0;
    EGLint minor = 0;
    if (eglInitialize(display_, &major, &minor) == EGL_FALSE) failEgl("eglInitialize");
    initialized_ = true;
    const char* exts = eglQueryString(display_, EGL_EXTENSIONS);
    if (!hasExtension(exts, "EGL_KHR_no_config_context") &&
        !hasExtension(exts, "EGL_MESA_configless_context")) {
      throw BackendError("the EGL display lacks EGL_KHR_no_config_context");
    }
    if (!hasExtension(exts, "EGL_KHR_surfaceless_context"))
      throw BackendError("the EGL display lacks EGL_KHR_surfaceless_context");
    createContext();
  }

  ~EglContext() override {
    if (context_ != EGL_NO_CONTEXT) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
    }
    for (EGLContext old : abandoned_) eglDestroyContext(display_, old);
    if (initialized_) eglTerminate(display_);
  }

  void makeCurrent() override {
    // The bound API is per thread; a later call may come from another thread.
    if (eglBindAPI(EGL_OPENGL_API) == EGL_FALSE) failEgl("eglBindAPI(EGL_OPENGL_API)");
    if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) == EGL_FALSE)
      failEgl("eglMakeCurrent (surfaceless)");
  }

  void release() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }

  void renew() override {
    release();
    eglDestroyContext(display_, context_);
    context_ = EGL_NO_CONTEXT;
    createContext();
  }

  void abandon() override {
    release();
    abandoned_.push_back(context_);
    context_ = EGL_NO_CONTEXT;
    createContext();
  }

  ProcLoader loader() const override { return &eglLoader; }
  const char* platform() const override { return platform_; }

 private:
  void createContext() {
    if (eglBindAPI(EGL_OPENGL_API) == EGL_FALSE) failEgl("eglBindAPI(EGL_OPENGL_API)");
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                              3,
                              EGL_CONTEXT_MINOR_VERSION,
                              3,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_NONE};
    context_ = eglCreateContext(display_, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (context_ == EGL_NO_CONTEXT) failEgl("eglCreateContext (OpenGL 3.3 core, no config)");
  }

  EGLDisplay display_;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::vector<EGLContext> abandoned_;  // abandon(): destroyed only with the display
  bool initialized_ = false;
  const char* platform_;
};

const char* clientExtensions() {
  // Querying EGL_NO_DISPLAY needs EGL_EXT_client_extensions; without it the call fails.
  const char* exts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (exts == nullptr)
    throw BackendError("EGL has no client extensions (EGL_EXT_client_extensions)");
  return exts;
}

}  // namespace

std::unique_ptr<Context> createEglSurfacelessContext() {
  const char* exts = clientExtensions();
  if (!hasExtension(exts, "EGL_MESA_platform_surfaceless"))
    throw BackendError("EGL lacks EGL_MESA_platform_surfaceless");
  auto get_display = eglProc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  EGLDisplay display = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) failEgl("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)");
  return std::make_unique<EglContext>(display, "egl");
}

namespace {

struct DeviceList {
  std::vector<EGLDeviceEXT> devices;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_string = nullptr;

  bool isSoftware(std::size_t i) const {
    return hasExtension(query_string(devices[i], EGL_EXTENSIONS), "EGL_MESA_device_software");
  }
};

DeviceList queryDevices() {
  const char* exts = clientExtensions();
  if (!hasExtension(exts, "EGL_EXT_device_enumeration") &&
      !hasExtension(exts, "EGL_EXT_device_base")) {
    throw BackendError("EGL lacks EGL_EXT_device_enumeration");
  }
  if (!hasExtension(exts, "EGL_EXT_platform_device"))
    throw BackendError("EGL lacks EGL_EXT_platform_device");
  auto query_devices = eglProc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
  DeviceList list;
  list.query_string = eglProc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
  EGLint count = 0;
  if (query_devices(0, nullptr, &count) == EGL_FALSE) failEgl("eglQueryDevicesEXT");
  list.devices.resize(static_cast<std::size_t>(count));
  if (count > 0 && query_devices(count, list.devices.data(), &count) == EGL_FALSE)
    failEgl("eglQueryDevicesEXT");
  list.devices.resize(static_cast<std::size_t>(count));
  return list;
}

int chooseDevice(const DeviceList& list, int device) {
  const std::size_t n = list.devices.size();
  if (device >= 0) {
    if (static_cast<std::size_t>(device) >= n) {
      throw BackendError(fmt::format("EGL device {} does not exist (found {} device{})", device, n,
                                     n == 1 ? "" : "s"));
    }
    if (list.isSoftware(static_cast<std::size_t>(device))) {
      throw BackendError(fmt::format(
          "EGL device {} is Mesa's software device, not a GPU (use gl:egl:llvmpipe)", device));
    }
    return device;
  }
  std::size_t software = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!list.isSoftware(i)) return static_cast<int>(i);
    ++software;
  }
  if (n == 0) throw BackendError("no EGL device with a GPU (found no EGL devices)");
  throw BackendError(fmt::format("no EGL device with a GPU (found only the software device{})",
                                 software > 1 ? "s" : ""));
}

}  // namespace

int findEglDevice(int device) { return chooseDevice(queryDevices(), device); }

std::unique_ptr<Context> createEglDeviceContext(int device) {
  const DeviceList list = queryDevices();
  const int index = chooseDevice(list, device);
  auto get_display = eglProc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  EGLDisplay display =
      get_display(EGL_PLATFORM_DEVICE_EXT, list.devices[static_cast<std::size_t>(index)], nullptr);
  if (display == EGL_NO_DISPLAY) failEgl("eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT)");
  return std::make_unique<EglContext>(display, "egl-device");
}

}  // namespace rc::gl
