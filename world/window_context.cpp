#include "window_context.h"

#include <EGL/eglext.h>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#ifdef VIPER_WORLD_WITH_X11
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#endif

namespace viper {
namespace world {

namespace {
[[noreturn]] void fail(const char* step) {
  char code[16];
  snprintf(code, sizeof(code), "0x%04x", eglGetError());
  throw std::runtime_error(std::string("EGL: ") + step + " failed (error " + code + ")");
}
}  // namespace

WindowContext::~WindowContext() {
  if (display_ != EGL_NO_DISPLAY) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
    if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
    eglTerminate(display_);
  }
#ifdef VIPER_WORLD_WITH_X11
  if (x_display_) {
    if (x_window_) XDestroyWindow(static_cast<Display*>(x_display_), x_window_);
    XCloseDisplay(static_cast<Display*>(x_display_));
  }
#endif
}

bool WindowContext::open(int width, int height) {
#ifdef VIPER_WORLD_WITH_X11
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name) return false;
  Display* x = XOpenDisplay(name);
  if (!x) return false;
  EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_X11_KHR, x, nullptr);
  EGLint major = 0, minor = 0;
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_WINDOW_BIT, EGL_RENDERABLE_TYPE,
                                   EGL_OPENGL_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8,
                                   EGL_BLUE_SIZE, 8, EGL_DEPTH_SIZE, 24, EGL_NONE};
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLConfig config;
  EGLint count = 0, visual_id = 0;
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor) ||
      !eglChooseConfig(display, config_attribs, &config, 1, &count) || count < 1 ||
      !eglGetConfigAttrib(display, config, EGL_NATIVE_VISUAL_ID, &visual_id)) {
    if (display != EGL_NO_DISPLAY) eglTerminate(display);
    XCloseDisplay(x);
    return false;
  }
  // The window needs the visual of the chosen EGL config.
  XVisualInfo templ;
  templ.visualid = VisualID(visual_id);
  int visuals = 0;
  XVisualInfo* vi = XGetVisualInfo(x, VisualIDMask, &templ, &visuals);
  Window root = DefaultRootWindow(x);
  XSetWindowAttributes attrs{};
  attrs.colormap = XCreateColormap(x, root, vi ? vi->visual : DefaultVisual(x, DefaultScreen(x)), AllocNone);
  attrs.event_mask = StructureNotifyMask;
  Window w = XCreateWindow(x, root, 0, 0, unsigned(width), unsigned(height), 0,
                           vi ? vi->depth : DefaultDepth(x, DefaultScreen(x)), InputOutput,
                           vi ? vi->visual : DefaultVisual(x, DefaultScreen(x)),
                           CWColormap | CWEventMask, &attrs);
  if (vi) XFree(vi);
  XStoreName(x, w, "viper world");
  XMapWindow(x, w);
  XFlush(x);
  x_display_ = x;
  x_window_ = w;
  display_ = display;
  EGLNativeWindowType native = w;
  surface_ = eglCreateWindowSurface(display, config, native, nullptr);
  if (surface_ == EGL_NO_SURFACE || !eglBindAPI(EGL_OPENGL_API) ||
      (context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs)) == EGL_NO_CONTEXT ||
      !eglMakeCurrent(display, surface_, surface_, context_)) {
    fail("window mode: eglCreateWindowSurface/eglCreateContext/eglMakeCurrent");
  }
  return true;
#else
  (void)width;
  (void)height;
  return false;
#endif
}

void WindowContext::swap() { eglSwapBuffers(display_, surface_); }

}  // namespace world
}  // namespace viper
