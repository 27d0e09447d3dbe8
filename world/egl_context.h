// OpenGL 3.3 core context: headless on Mesa's surfaceless EGL platform with a pbuffer surface of
// the frame size (the program draws to the default framebuffer and swaps once per frame), or, on
// request and where an X display is available, in an X11 window through EGL's X11 platform.
#pragma once

#include <EGL/egl.h>

namespace viper {
namespace world {

/// Owns the EGL display, pbuffer surface and context; current on the calling thread after create().
class EglContext {
 public:
  EglContext() = default;
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Creates a width x height pbuffer with RGBA8 + 24-bit depth and makes a GL 3.3 core context
  /// current. Throws std::runtime_error naming the EGL step that failed.
  void create(int width, int height);
  /// Like create(), but in an X11 window when this build has X11 and $DISPLAY opens; returns
  /// false (and leaves nothing behind) when no window could be made, so the caller can fall back.
  bool createWindow(int width, int height);
  /// eglSwapBuffers on the pbuffer (the frame boundary a capture layer sees).
  void swap();

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLSurface surface_ = EGL_NO_SURFACE;
  EGLContext context_ = EGL_NO_CONTEXT;
  void* x_display_ = nullptr;      ///< Display* of the window mode
  unsigned long x_window_ = 0;     ///< Window of the window mode
};

}  // namespace world
}  // namespace viper
