#include "gl_real.h"
#include "hooks.h"

#include <dlfcn.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <mutex>

namespace viper {
namespace capture {

namespace {

using DlsymFn = void* (*)(void*, const char*);

VIPER_NO_SANITIZE DlsymFn lookupRealDlsym() {
  // dlvsym is not interposed, so it reaches glibc's dlsym whichever version this glibc has.
  // (A plain array: no inline library code, which would be instrumented, on this path.)
  static const char* const kVersions[] = {"GLIBC_2.34", "GLIBC_2.2.5", "GLIBC_2.17", "GLIBC_2.0"};
  for (size_t i = 0; i < sizeof(kVersions) / sizeof(kVersions[0]); ++i) {
    if (void* f = dlvsym(RTLD_NEXT, "dlsym", kVersions[i])) return reinterpret_cast<DlsymFn>(f);
  }
  return nullptr;
}

void* openFirst(std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (void* h = dlopen(n, RTLD_LAZY | RTLD_LOCAL)) return h;
  }
  return nullptr;
}

using GetProcFn = void* (*)(const char*);

RealGl loadRealGl() {
  RealGl t;
  void* opengl = openFirst({"libOpenGL.so.0", "libGL.so.1"});
  auto egl_proc = reinterpret_cast<GetProcFn>(realEglFunction("eglGetProcAddress"));
  auto lookup = [&](const char* name) -> void* {
    void* f = opengl ? realDlsym(opengl, name) : nullptr;
    if (!f && egl_proc) f = egl_proc(name);
    if (!f) std::fprintf(stderr, "[viper capture] real %s not found\n", name);
    return f;
  };
#define VIPER_LOAD_MEMBER(type, name) t.name = reinterpret_cast<type>(lookup("gl" #name));
  VIPER_REAL_GL_FUNCTIONS(VIPER_LOAD_MEMBER)
#undef VIPER_LOAD_MEMBER
  return t;
}

}  // namespace

VIPER_NO_SANITIZE void* realDlsymFunction() {
  // Not a function-local static: its guard (__cxa_guard_acquire) is intercepted by ThreadSanitizer,
  // whose runtime calls this from its own start. Every thread finds the same function, so a race
  // between two first calls only looks it up twice.
  static DlsymFn real = nullptr;
  DlsymFn f = __atomic_load_n(&real, __ATOMIC_ACQUIRE);
  if (!f) {
    f = lookupRealDlsym();
    __atomic_store_n(&real, f, __ATOMIC_RELEASE);
  }
  return reinterpret_cast<void*>(f);
}

VIPER_NO_SANITIZE void* realDlsym(void* handle, const char* name) {
  const auto f = reinterpret_cast<DlsymFn>(realDlsymFunction());
  return f ? f(handle, name) : nullptr;
}

const RealGl& gl() {
  static const RealGl table = loadRealGl();
  return table;
}

bool glHasExtension(const char* name) {
  const RealGl& g = gl();
  if (glVersionAtLeast(3, 0)) {
    const GLint count = glInt(GL_NUM_EXTENSIONS);
    for (GLint i = 0; g.GetStringi && i < count; ++i) {
      const GLubyte* e = g.GetStringi(GL_EXTENSIONS, static_cast<GLuint>(i));
      if (e && std::strcmp(reinterpret_cast<const char*>(e), name) == 0) return true;
    }
    return false;
  }
  const GLubyte* all = g.GetString ? g.GetString(GL_EXTENSIONS) : nullptr;
  if (!all) return false;
  const std::string list = std::string(" ") + reinterpret_cast<const char*>(all) + " ";
  return list.find(std::string(" ") + name + " ") != std::string::npos;
}

void* realEglFunction(const char* name) {
  static void* egl = openFirst({"libEGL.so.1", "libEGL.so"});
  return egl ? realDlsym(egl, name) : nullptr;
}

void* realGlxFunction(const char* name) {
  static void* glx = openFirst({"libGLX.so.0", "libGL.so.1"});
  return glx ? realDlsym(glx, name) : nullptr;
}

}  // namespace capture
}  // namespace viper
