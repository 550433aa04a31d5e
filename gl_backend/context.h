// Context providers: an offscreen GL 3.3 core context from EGL (surfaceless platform or
// an EGL device) or OSMesa. The backend renders into its own FBO, so no provider has a
// window or a usable default framebuffer. Providers do not pick the Gallium driver:
// the caller sets GALLIUM_DRIVER before the first one is created.
#pragma once

#include <memory>
#include <string>

namespace rc::gl {

// Kept free of GL headers: osmesa.h brings its own GL/gl.h, which clashes with
// GL/glcorearb.h in one translation unit.
using ProcAddress = void (*)();
using ProcLoader = ProcAddress (*)(const char* name);

class Context {
 public:
  Context() = default;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  virtual ~Context() = default;

  // Binds the context to the calling thread; throws BackendError on failure.
  virtual void makeCurrent() = 0;
  // Unbinds it, so that another thread may bind it later.
  virtual void release() = 0;
  // Replaces the GL context by a new one on the same display (the driver stays loaded),
  // unbound; every GL object of the old one is gone. Throws BackendError on failure.
  virtual void renew() = 0;
  // Like renew(), but the old context is never destroyed while the provider lives, only
  // unbound: for a driver that must not see a context destroyed (zink on Mesa 22 keeps
  // pointers into a destroyed context's batch states; docs/gl_backend.md).
  virtual void abandon() = 0;
  // The provider's getProcAddress (eglGetProcAddress / OSMesaGetProcAddress).
  virtual ProcLoader loader() const = 0;
  // "egl", "egl-device" or "osmesa" (frame.json "platform").
  virtual const char* platform() const = 0;
};

// EGL_PLATFORM_SURFACELESS_MESA with a configless context. Throws BackendError saying
// which EGL step or extension failed.
std::unique_ptr<Context> createEglSurfacelessContext();

// EGL_EXT_platform_device. device < 0 picks the first hardware device; Mesa's software
// device (EGL_MESA_device_software) is never picked. Throws BackendError when there is
// no such device, e.g. "no EGL device with a GPU (found only the software device)".
std::unique_ptr<Context> createEglDeviceContext(int device);

// The index createEglDeviceContext(device) would use, without creating anything; throws
// the same BackendError when there is no such hardware device.
int findEglDevice(int device);

// OSMesa with a core-profile context, from `mesa_dir`'s OSMesa library when not empty
// (the first call in a process decides which library is loaded). Throws BackendError
// when the build has no OSMesa.
std::unique_ptr<Context> createOsMesaContext(const std::string& mesa_dir = "");

}  // namespace rc::gl
