// A headless OpenGL 3.3 core context with a pbuffer surface of a given size, through EGL: what
// test_scene and world render into.
#pragma once

#include <EGL/egl.h>

#include <cstdint>
#include <string>

namespace viper {
namespace gl_common {

/// Owns an EGL display, an RGBA8 + depth 24 pbuffer surface and a current OpenGL 3.3 core
/// context. The surface is the default framebuffer (framebuffer 0) of the context.
class HeadlessEglContext {
 public:
  /// Tries Mesa's surfaceless platform first, then EGL_DEFAULT_DISPLAY, then the first EGL device
  /// (EGL_EXT_platform_device: a GPU driver without an X server). Throws std::runtime_error
  /// saying which step failed (with the EGL error code) if neither gives a context.
  HeadlessEglContext(uint32_t width, uint32_t height);
  ~HeadlessEglContext();
  HeadlessEglContext(const HeadlessEglContext&) = delete;
  HeadlessEglContext& operator=(const HeadlessEglContext&) = delete;

  /// eglSwapBuffers on the pbuffer (a no-op for the pixels, but the frame boundary capture layers
  /// watch). Throws std::runtime_error on failure.
  void swapBuffers();

  /// Which platform was used ("surfaceless", or the fallback and why surfaceless failed).
  const std::string& platform() const { return platform_; }

 private:
  bool tryDisplay(EGLDisplay display, uint32_t width, uint32_t height, std::string& error);

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLSurface surface_ = EGL_NO_SURFACE;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string platform_;
};

}  // namespace gl_common
}  // namespace viper
