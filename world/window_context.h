// --window: an OpenGL 3.3 core context in an X11 window, through EGL's X11 platform, where this
// build has X11 and an X display opens. Headless rendering uses gl_common's HeadlessEglContext.
#pragma once

#include <EGL/egl.h>

namespace viper {
namespace world {

/// Owns the X11 window, its EGL display, window surface and context; current on the calling
/// thread after open() returned true.
class WindowContext {
 public:
  WindowContext() = default;
  ~WindowContext();
  WindowContext(const WindowContext&) = delete;
  WindowContext& operator=(const WindowContext&) = delete;

  /// Opens a width x height window with RGB8 + 24-bit depth and makes a GL 3.3 core context
  /// current. Returns false (and leaves nothing behind) when this build has no X11 or $DISPLAY
  /// does not open, so the caller can fall back to headless; throws std::runtime_error naming the
  /// EGL step when the window opened but no context could be made in it.
  bool open(int width, int height);
  /// eglSwapBuffers on the window (the frame boundary a capture layer sees).
  void swap();

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLSurface surface_ = EGL_NO_SURFACE;
  EGLContext context_ = EGL_NO_CONTEXT;
  void* x_display_ = nullptr;      ///< Display* of the window
  unsigned long x_window_ = 0;     ///< Window
};

}  // namespace world
}  // namespace viper
