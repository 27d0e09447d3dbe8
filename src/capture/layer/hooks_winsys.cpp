// Exported EGL/GLX entry points, the GetProcAddress functions and dlsym, so that programs that
// load GL functions at run time also reach the interceptor.
#include "hooks.h"
#include "interceptor.h"

#include <EGL/egl.h>
#include <dlfcn.h>
#include <link.h>

#include <cstring>
#include <mutex>
#include <unordered_set>

using viper::capture::Interceptor;
using viper::capture::realDlsym;
using viper::capture::realEglFunction;
using viper::capture::realGlxFunction;
using viper::capture::wrapperFor;

#define VIPER_EXPORT extern "C" __attribute__((visibility("default")))

// GLX types without pulling in GL/gl.h (it clashes with glcorearb.h).
typedef struct _XDisplay Display;
typedef unsigned long GLXDrawable;
typedef struct __GLXcontextRec* GLXContext;
typedef void (*GlxProc)();

namespace {

constexpr int kGlxWidth = 0x801D;
constexpr int kGlxHeight = 0x801E;

template <typename F>
F real(F, const char* name, bool glx) {
  return reinterpret_cast<F>(glx ? realGlxFunction(name) : realEglFunction(name));
}
#define REAL_EGL(fn) real(&::fn, #fn, false)
#define REAL_GLX(fn) real(&::fn, #fn, true)

inline Interceptor* active() {
  Interceptor& i = Interceptor::instance();
  return i.enabled() ? &i : nullptr;
}

void eglSurfaceSize(EGLDisplay dpy, EGLSurface surface, int& w, int& h) {
  static auto query = reinterpret_cast<EGLBoolean (*)(EGLDisplay, EGLSurface, EGLint, EGLint*)>(
      realEglFunction("eglQuerySurface"));
  EGLint ew = 0, eh = 0;
  if (surface != EGL_NO_SURFACE && query) {
    query(dpy, surface, EGL_WIDTH, &ew);
    query(dpy, surface, EGL_HEIGHT, &eh);
  }
  w = ew, h = eh;
}

void glxDrawableSize(Display* dpy, GLXDrawable drawable, int& w, int& h) {
  static auto query =
      reinterpret_cast<void (*)(Display*, GLXDrawable, int, unsigned int*)>(realGlxFunction("glXQueryDrawable"));
  unsigned int gw = 0, gh = 0;
  if (drawable && query) {
    query(dpy, drawable, kGlxWidth, &gw);
    query(dpy, drawable, kGlxHeight, &gh);
  }
  w = static_cast<int>(gw), h = static_cast<int>(gh);
}

// The file name of the object holding `address` (null if none).
VIPER_NO_SANITIZE const char* objectName(const void* address) {
  Dl_info info;
  if (!dladdr(address, &info) || !info.dli_fname) return nullptr;
  const char* base = std::strrchr(info.dli_fname, '/');
  return base ? base + 1 : info.dli_fname;
}

// Whether `base` (a file name) contains one of `names`. (Plain arrays: no inline library code,
// which the sanitized build would instrument, on the dlsym path; see VIPER_NO_SANITIZE.)
template <size_t N>
VIPER_NO_SANITIZE bool nameHasAny(const char* base, const char* const (&names)[N]) {
  for (size_t i = 0; i < N; ++i)
    if (std::strstr(base, names[i])) return true;
  return false;
}

// Libraries of the GL stack itself must get the real functions from dlsym.
VIPER_NO_SANITIZE bool calledFromDriver(const char* base) {
  static const char* const kStack[] = {"libEGL", "libGL", "libOpenGL", "libGLX", "libGLdispatch", "libgbm", "mesa", "dri",
                                       "gallium", "libnvidia"};
  return base && nameHasAny(base, kStack);
}

// A sanitizer runtime looks up the functions it intercepts with dlsym at its start, before it can
// forward the dlopen that nextSymbol makes (it intercepts dlopen too) and before instrumented code
// may run. `capture` keeps a preloaded runtime before this library, so what follows this library
// is what follows the runtime: plain RTLD_NEXT from here is right.
VIPER_NO_SANITIZE bool calledFromSanitizer(const char* base) {
  static const char* const kRuntimes[] = {"libasan", "libubsan", "libtsan", "liblsan"};
  return base && nameHasAny(base, kRuntimes);
}

// RTLD_NEXT relative to the caller, not to this library: search the objects loaded after it.
VIPER_NO_SANITIZE void* nextSymbol(const void* caller, const char* name) {
  Dl_info info;
  link_map* map = nullptr;
  if (!dladdr1(caller, &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) || !map)
    return realDlsym(RTLD_NEXT, name);
  for (link_map* l = map->l_next; l; l = l->l_next) {
    if (!l->l_name || !l->l_name[0]) continue;
    void* h = dlopen(l->l_name, RTLD_LAZY | RTLD_NOLOAD);
    if (!h) continue;
    void* f = realDlsym(h, name);
    dlclose(h);
    if (f) return f;
  }
  return nullptr;
}

// Pbuffer surfaces: nobody sees them but through GL reads, so the swap skips the copy to them.
// Never destroyed (as the interceptor): when a thread calls exit(), static destructors run while
// the program's other threads may still swap.
std::mutex g_pbuffers_mutex;  // trivially destructible in glibc
std::unordered_set<EGLSurface>& pbuffers() {
  static auto* set = new std::unordered_set<EGLSurface>;
  return *set;
}

bool isPbuffer(EGLSurface surface) {
  std::lock_guard<std::mutex> lock(g_pbuffers_mutex);
  return pbuffers().count(surface) > 0;
}

}  // namespace

VIPER_EXPORT EGLSurface eglCreatePbufferSurface(EGLDisplay dpy, EGLConfig config, const EGLint* attribs) {
  static auto fn = REAL_EGL(eglCreatePbufferSurface);
  EGLSurface s = fn(dpy, config, attribs);
  if (s != EGL_NO_SURFACE) {
    std::lock_guard<std::mutex> lock(g_pbuffers_mutex);
    pbuffers().insert(s);
  }
  return s;
}

VIPER_EXPORT EGLBoolean eglDestroySurface(EGLDisplay dpy, EGLSurface surface) {
  static auto fn = REAL_EGL(eglDestroySurface);
  {
    std::lock_guard<std::mutex> lock(g_pbuffers_mutex);
    pbuffers().erase(surface);
  }
  return fn(dpy, surface);
}

VIPER_EXPORT EGLBoolean eglMakeCurrent(EGLDisplay dpy, EGLSurface draw, EGLSurface read, EGLContext ctx) {
  static auto fn = REAL_EGL(eglMakeCurrent);
  static auto current = REAL_EGL(eglGetCurrentContext);
  if (Interceptor* i = active())
    if (!current || current() != ctx) i->beforeMakeCurrent();
  const EGLBoolean ok = fn(dpy, draw, read, ctx);
  if (Interceptor* i = active()) {
    if (ok) {
      int w = 0, h = 0;
      eglSurfaceSize(dpy, draw, w, h);
      i->onMakeCurrent(ctx == EGL_NO_CONTEXT ? nullptr : ctx, w, h);
    }
  }
  return ok;
}

VIPER_EXPORT EGLBoolean eglDestroyContext(EGLDisplay dpy, EGLContext ctx) {
  static auto fn = REAL_EGL(eglDestroyContext);
  const EGLBoolean ok = fn(dpy, ctx);
  if (ok)
    if (Interceptor* i = active()) i->contextDestroyed(ctx);
  return ok;
}

VIPER_EXPORT EGLBoolean eglSwapBuffers(EGLDisplay dpy, EGLSurface surface) {
  static auto fn = REAL_EGL(eglSwapBuffers);
  if (Interceptor* i = active()) {
    int w = 0, h = 0;
    eglSurfaceSize(dpy, surface, w, h);
    i->beforeSwap(w, h, isPbuffer(surface));
  }
  return fn(dpy, surface);
}

VIPER_EXPORT __eglMustCastToProperFunctionPointerType eglGetProcAddress(const char* name) {
  static auto fn = REAL_EGL(eglGetProcAddress);
  if (void* w = wrapperFor(name)) return reinterpret_cast<__eglMustCastToProperFunctionPointerType>(w);
  return fn ? fn(name) : nullptr;
}

VIPER_EXPORT int glXMakeCurrent(Display* dpy, GLXDrawable drawable, GLXContext ctx) {
  static auto fn = reinterpret_cast<int (*)(Display*, GLXDrawable, GLXContext)>(realGlxFunction("glXMakeCurrent"));
  static auto current = reinterpret_cast<GLXContext (*)()>(realGlxFunction("glXGetCurrentContext"));
  if (Interceptor* i = active())
    if (!current || current() != ctx) i->beforeMakeCurrent();
  const int ok = fn(dpy, drawable, ctx);
  if (Interceptor* i = active()) {
    if (ok) {
      int w = 0, h = 0;
      glxDrawableSize(dpy, drawable, w, h);
      i->onMakeCurrent(ctx, w, h);
    }
  }
  return ok;
}

VIPER_EXPORT int glXMakeContextCurrent(Display* dpy, GLXDrawable draw, GLXDrawable read, GLXContext ctx) {
  static auto fn = reinterpret_cast<int (*)(Display*, GLXDrawable, GLXDrawable, GLXContext)>(
      realGlxFunction("glXMakeContextCurrent"));
  static auto current = reinterpret_cast<GLXContext (*)()>(realGlxFunction("glXGetCurrentContext"));
  if (Interceptor* i = active())
    if (!current || current() != ctx) i->beforeMakeCurrent();
  const int ok = fn(dpy, draw, read, ctx);
  if (Interceptor* i = active()) {
    if (ok) {
      int w = 0, h = 0;
      glxDrawableSize(dpy, draw, w, h);
      i->onMakeCurrent(ctx, w, h);
    }
  }
  return ok;
}

VIPER_EXPORT void glXDestroyContext(Display* dpy, GLXContext ctx) {
  static auto fn = reinterpret_cast<void (*)(Display*, GLXContext)>(realGlxFunction("glXDestroyContext"));
  fn(dpy, ctx);
  if (Interceptor* i = active()) i->contextDestroyed(ctx);
}

VIPER_EXPORT void glXSwapBuffers(Display* dpy, GLXDrawable drawable) {
  static auto fn = reinterpret_cast<void (*)(Display*, GLXDrawable)>(realGlxFunction("glXSwapBuffers"));
  if (Interceptor* i = active()) {
    int w = 0, h = 0;
    glxDrawableSize(dpy, drawable, w, h);
    i->beforeSwap(w, h, false);
  }
  fn(dpy, drawable);
}

VIPER_EXPORT GlxProc glXGetProcAddress(const unsigned char* name) {
  static auto fn = reinterpret_cast<GlxProc (*)(const unsigned char*)>(realGlxFunction("glXGetProcAddress"));
  if (void* w = wrapperFor(reinterpret_cast<const char*>(name))) return reinterpret_cast<GlxProc>(w);
  return fn ? fn(name) : nullptr;
}

VIPER_EXPORT GlxProc glXGetProcAddressARB(const unsigned char* name) { return glXGetProcAddress(name); }

VIPER_EXPORT VIPER_NO_SANITIZE void* dlsym(void* __restrict handle, const char* __restrict name) {
  const void* caller = __builtin_return_address(0);
  const char* object = objectName(caller);
  if (calledFromSanitizer(object)) return realDlsym(handle, name);
  if (handle == RTLD_NEXT) return nextSymbol(caller, name);
  if (!calledFromDriver(object)) {
    if (void* w = wrapperFor(name)) {
      // Only where the library asked for really has the symbol (dlsym(libGL, "eglFoo") stays null).
      if (realDlsym(handle, name)) return w;
    }
  }
  return realDlsym(handle, name);
}

namespace viper {
namespace capture {

VIPER_NO_SANITIZE void* wrapperForWinsys(const char* name) {
#define VIPER_ENTRY(f) VIPER_HOOK_ENTRY(f)
  static const HookEntry kEntries[] = {
      VIPER_ENTRY(eglCreatePbufferSurface), VIPER_ENTRY(eglDestroySurface), VIPER_ENTRY(eglMakeCurrent),        VIPER_ENTRY(eglDestroyContext),        VIPER_ENTRY(eglSwapBuffers),   VIPER_ENTRY(eglGetProcAddress),
      VIPER_ENTRY(glXMakeCurrent),        VIPER_ENTRY(glXMakeContextCurrent), VIPER_ENTRY(glXDestroyContext), VIPER_ENTRY(glXSwapBuffers),
      VIPER_ENTRY(glXGetProcAddress),     VIPER_ENTRY(glXGetProcAddressARB),
  };
#undef VIPER_ENTRY
  return findHook(kEntries, name);
}

}  // namespace capture
}  // namespace viper
