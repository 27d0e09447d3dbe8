// A headless OpenGL 3.3 core context with a pbuffer surface of a given size, through EGL.
#pragma once

#include <EGL/egl.h>

#include <cstdint>
#include <string>

namespace viper {
namespace scene {

/// Owns an EGL display, a pbuffer surface and a current OpenGL 3.3 core context. The surface is the
/// default framebuffer (framebuffer 0) of the context.
class EglContext {
 public:
  /// Tries Mesa's surfaceless platform first, then EGL_DEFAULT_DISPLAY. Throws std::runtime_error
  /// saying which step failed (with the EGL error code) if neither gives a context.
  EglContext(uint32_t width, uint32_t height);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// eglSwapBuffers on the pbuffer (a no-op for the pixels, but the frame boundary capture layers
  /// watch). Throws std::runtime_error on failure.
  void swapBuffers();

  /// Which platform was used and the GL renderer, for the log.
  const std::string& platform() const { return platform_; }

 private:
  bool tryDisplay(EGLDisplay display, uint32_t width, uint32_t height, std::string& error);

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLSurface surface_ = EGL_NO_SURFACE;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string platform_;
};

}  // namespace scene
}  // namespace viper
