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

// glXMakeCurrent and glXMakeContextCurrent (`make_current` calls the real one): the interceptor is
// told before the current context changes, and after it has with the size of `draw`.
template <typename MakeCurrent>
int makeGlxCurrent(Display* dpy, GLXDrawable draw, GLXContext ctx, MakeCurrent make_current) {
  static auto current = reinterpret_cast<GLXContext (*)()>(realGlxFunction("glXGetCurrentContext"));
  if (Interceptor* i = Interceptor::active())
    if (!current || current() != ctx) i->beforeMakeCurrent();
  const int ok = make_current();
  if (Interceptor* i = Interceptor::active()) {
    if (ok) {
      int w = 0, h = 0;
      glxDrawableSize(dpy, draw, w, h);
      i->onMakeCurrent(ctx, w, h);
    }
  }
  return ok;
}

// Plain loops instead of strrchr and strstr on the dlsym path: a sanitizer runtime intercepts
// those, and its interceptors cannot run while it is still looking up what they forward to.
VIPER_NO_SANITIZE const char* baseName(const char* path) {
  const char* base = path;
  for (const char* p = path; *p; ++p)
    if (*p == '/') base = p + 1;
  return base;
}

VIPER_NO_SANITIZE bool contains(const char* text, const char* part) {
  for (; *text; ++text) {
    size_t i = 0;
    while (part[i] && text[i] == part[i]) ++i;
    if (!part[i]) return true;
  }
  return false;
}

// The file name of the object holding `address` (null if none). (dladdr is not intercepted.)
VIPER_NO_SANITIZE const char* objectName(const void* address) {
  Dl_info info;
  if (!dladdr(address, &info) || !info.dli_fname) return nullptr;
  return baseName(info.dli_fname);
}

// Whether `base` (a file name) contains one of `names`. (Plain arrays: no inline library code,
// which the sanitized build would instrument, on the dlsym path; see VIPER_NO_SANITIZE.)
template <size_t N>
VIPER_NO_SANITIZE bool nameHasAny(const char* base, const char* const (&names)[N]) {
  for (size_t i = 0; i < N; ++i)
    if (contains(base, names[i])) return true;
  return false;
}

// Libraries of the GL stack itself must get the real functions from dlsym.
VIPER_NO_SANITIZE bool calledFromDriver(const char* base) {
  static const char* const kStack[] = {"libEGL", "libGL", "libOpenGL", "libGLX", "libGLdispatch", "libgbm", "mesa", "dri",
                                       "gallium", "libnvidia"};
  return base && nameHasAny(base, kStack);
}

// A sanitizer runtime looks up the functions it intercepts with dlsym at its start, before it can
// forward a dlopen (it intercepts dlopen too) and before instrumented code may run: its calls go
// to glibc's dlsym as they are (see dlsym below).
VIPER_NO_SANITIZE bool calledFromSanitizer(const char* base) {
  static const char* const kRuntimes[] = {"libasan", "libubsan", "libtsan", "liblsan"};
  return base && nameHasAny(base, kRuntimes);
}

// RTLD_NEXT relative to the caller, not to this library: search the objects loaded after it.
// (Where the exported dlsym cannot hand RTLD_NEXT to glibc with the caller's return address: not
// x86-64.)
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
  if (Interceptor* i = Interceptor::active())
    if (!current || current() != ctx) i->beforeMakeCurrent();
  const EGLBoolean ok = fn(dpy, draw, read, ctx);
  if (Interceptor* i = Interceptor::active()) {
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
    if (Interceptor* i = Interceptor::active()) i->contextDestroyed(ctx);
  return ok;
}

VIPER_EXPORT EGLBoolean eglSwapBuffers(EGLDisplay dpy, EGLSurface surface) {
  static auto fn = REAL_EGL(eglSwapBuffers);
  if (Interceptor* i = Interceptor::active()) {
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
  return makeGlxCurrent(dpy, drawable, ctx, [&] { return fn(dpy, drawable, ctx); });
}

VIPER_EXPORT int glXMakeContextCurrent(Display* dpy, GLXDrawable draw, GLXDrawable read, GLXContext ctx) {
  static auto fn = reinterpret_cast<int (*)(Display*, GLXDrawable, GLXDrawable, GLXContext)>(
      realGlxFunction("glXMakeContextCurrent"));
  return makeGlxCurrent(dpy, draw, ctx, [&] { return fn(dpy, draw, read, ctx); });
}

VIPER_EXPORT void glXDestroyContext(Display* dpy, GLXContext ctx) {
  static auto fn = reinterpret_cast<void (*)(Display*, GLXContext)>(realGlxFunction("glXDestroyContext"));
  fn(dpy, ctx);
  if (Interceptor* i = Interceptor::active()) i->contextDestroyed(ctx);
}

VIPER_EXPORT void glXSwapBuffers(Display* dpy, GLXDrawable drawable) {
  static auto fn = reinterpret_cast<void (*)(Display*, GLXDrawable)>(realGlxFunction("glXSwapBuffers"));
  if (Interceptor* i = Interceptor::active()) {
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

namespace {

// dlsym for everyone but a sanitizer runtime: wrappers for the GL names the interceptor hooks, and
// RTLD_NEXT relative to the caller (`caller`: the return address of the call to dlsym).
VIPER_NO_SANITIZE void* dlsymFrom(const void* caller, void* handle, const char* name) {
  const char* object = objectName(caller);
  if (handle == RTLD_NEXT) return nextSymbol(caller, name);
  if (!calledFromDriver(object)) {
    if (void* w = wrapperFor(name)) {
      // Only where the library asked for really has the symbol (dlsym(libGL, "eglFoo") stays null).
      if (realDlsym(handle, name)) return w;
    }
  }
  return realDlsym(handle, name);
}

}  // namespace

// Whether glibc's dlsym (in viper_real_dlsym) gets the call returning to `caller` unchanged: a
// sanitizer runtime's, and every RTLD_NEXT (on x86-64, where the jump keeps the caller's return
// address, which glibc reads to know whose "next" is meant).
extern "C" {
__attribute__((visibility("hidden"))) void* viper_real_dlsym = nullptr;
}
extern "C" __attribute__((visibility("hidden"), used)) VIPER_NO_SANITIZE bool viper_dlsym_forward(const void* caller,
                                                                                              void* handle) {
#if defined(__x86_64__)
  const bool next = handle == RTLD_NEXT;
#else
  const bool next = false;
  (void)handle;
#endif
  if (!next && !calledFromSanitizer(objectName(caller))) return false;
  viper_real_dlsym = viper::capture::realDlsymFunction();
  return viper_real_dlsym != nullptr;
}

#if defined(__x86_64__)
// Reached from the exported dlsym by a jump, with the caller's return address in place.
extern "C" __attribute__((visibility("hidden"), used)) VIPER_NO_SANITIZE void* viper_dlsym(void* handle,
                                                                                        const char* name) {
  return dlsymFrom(__builtin_return_address(0), handle, name);
}

// The exported dlsym. Calls with RTLD_NEXT, and a sanitizer runtime's calls (its own start looks
// up, with dlsym(RTLD_NEXT, ...), every function it intercepts), jump on to glibc's dlsym with the
// caller's return address where glibc looks for the caller, so RTLD_NEXT means the objects after
// the caller, wherever it and this library come in the program's libraries, as if this library
// did not export dlsym; and nothing instrumented or intercepted runs before a runtime is ready.
// (A C++ function cannot promise that tail call; this library's own call to glibc would make
// RTLD_NEXT the objects after this library, which are the runtime's own interceptors when the
// runtime comes after it. Before, RTLD_NEXT was searched object by object with dlopen(RTLD_NOLOAD),
// which runs initialisers again once exit() has run them down: a program's readlink looked up
// during LeakSanitizer's check at exit (apitrace's glretrace) restarted libasan and hung.) Every
// other call goes on to viper_dlsym, also with the caller's return address in place.
asm(R"(
  .text
  .globl dlsym
  .type dlsym, @function
  .p2align 4
dlsym:
  .cfi_startproc
  endbr64
  pushq %rdi
  .cfi_adjust_cfa_offset 8
  pushq %rsi
  .cfi_adjust_cfa_offset 8
  subq $8, %rsp
  .cfi_adjust_cfa_offset 8
  movq 24(%rsp), %rdi
  movq 16(%rsp), %rsi
  call viper_dlsym_forward
  addq $8, %rsp
  .cfi_adjust_cfa_offset -8
  popq %rsi
  .cfi_adjust_cfa_offset -8
  popq %rdi
  .cfi_adjust_cfa_offset -8
  testb %al, %al
  jz viper_dlsym
  jmp *viper_real_dlsym(%rip)
  .cfi_endproc
  .size dlsym, .-dlsym
)");
#else
// (No trampoline: a runtime's RTLD_NEXT is searched from this library instead, which is right when
// the runtime comes first in LD_PRELOAD, as `capture` sets it.)
VIPER_EXPORT VIPER_NO_SANITIZE void* dlsym(void* __restrict handle, const char* __restrict name) {
  const void* caller = __builtin_return_address(0);
  if (viper_dlsym_forward(caller, handle)) return realDlsym(handle, name);
  return dlsymFrom(caller, handle, name);
}
#endif

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
