#include "headless_egl_context.h"

#include <EGL/eglext.h>

#include <cstdio>
#include <stdexcept>

namespace viper {
namespace gl_common {
namespace {

std::string eglErrorText(const char* step) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "%s failed (EGL error 0x%04x)", step, static_cast<unsigned>(eglGetError()));
  return buffer;
}

}  // namespace

HeadlessEglContext::HeadlessEglContext(uint32_t width, uint32_t height) {
  std::string error;
  // Surfaceless Mesa needs no X server, no GPU and no device node, and supports pbuffers.
  const EGLDisplay surfaceless = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (surfaceless != EGL_NO_DISPLAY && tryDisplay(surfaceless, width, height, error)) {
    platform_ = "surfaceless";
    return;
  }
  const std::string surfaceless_error = surfaceless == EGL_NO_DISPLAY ? eglErrorText("eglGetPlatformDisplay") : error;
  const EGLDisplay fallback = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (fallback != EGL_NO_DISPLAY && tryDisplay(fallback, width, height, error)) {
    platform_ = "default display (surfaceless failed: " + surfaceless_error + ")";
    return;
  }
  const std::string default_error = fallback == EGL_NO_DISPLAY ? eglErrorText("eglGetDisplay") : error;
  // A GPU driver without Mesa's platforms (NVIDIA's EGL without an X server): its first device.
  const auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  EGLDeviceEXT devices[4];
  EGLint device_count = 0;
  if (query_devices && query_devices(4, devices, &device_count) && device_count > 0) {
    const EGLDisplay device = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
    if (device != EGL_NO_DISPLAY && tryDisplay(device, width, height, error)) {
      platform_ = "device platform (surfaceless failed: " + surfaceless_error + ")";
      return;
    }
  } else {
    error = "no EGL device";
  }
  throw std::runtime_error("no headless OpenGL 3.3 core context: surfaceless platform: " + surfaceless_error +
                           "; default display: " + default_error + "; device platform: " + error);
}

bool HeadlessEglContext::tryDisplay(EGLDisplay display, uint32_t width, uint32_t height, std::string& error) {
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    error = eglErrorText("eglInitialize");
    return false;
  }
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                      EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
                                      EGL_DEPTH_SIZE, 24, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &count) || count < 1) {
    error = count < 1 ? "no RGBA8 + depth24 pbuffer config for desktop OpenGL" : eglErrorText("eglChooseConfig");
    eglTerminate(display);
    return false;
  }
  const EGLint surface_attributes[] = {EGL_WIDTH, static_cast<EGLint>(width), EGL_HEIGHT, static_cast<EGLint>(height),
                                       EGL_NONE};
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  if (!eglBindAPI(EGL_OPENGL_API)) {
    error = eglErrorText("eglBindAPI(EGL_OPENGL_API)");
  } else if ((surface_ = eglCreatePbufferSurface(display, config, surface_attributes)) == EGL_NO_SURFACE) {
    error = eglErrorText("eglCreatePbufferSurface");
  } else if ((context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes)) == EGL_NO_CONTEXT) {
    error = eglErrorText("eglCreateContext(OpenGL 3.3 core)");
  } else if (!eglMakeCurrent(display, surface_, surface_, context_)) {
    error = eglErrorText("eglMakeCurrent");
  } else {
    display_ = display;
    return true;
  }
  if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display, context_);
  if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display, surface_);
  context_ = EGL_NO_CONTEXT;
  surface_ = EGL_NO_SURFACE;
  eglTerminate(display);
  return false;
}

HeadlessEglContext::~HeadlessEglContext() {
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
  eglDestroySurface(display_, surface_);
  eglTerminate(display_);
}

void HeadlessEglContext::swapBuffers() {
  if (!eglSwapBuffers(display_, surface_)) throw std::runtime_error(eglErrorText("eglSwapBuffers"));
}

}  // namespace gl_common
}  // namespace viper
