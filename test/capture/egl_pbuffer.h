// What the EGL test programs (gl_engine_program.cpp, gl_legacy_program.cpp,
// gl_fixed_function_program.cpp) share: a message and exit on failure, their common options, a
// shader compiled (gl_common's compileShader) or the program ended, and a pbuffer made current with
// an OpenGL context of their own version that they never tear down (the capture layer is tested on
// programs that exit so). Include after the program's GL header.
#pragma once

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "gl_common/shader_build.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

namespace viper {
namespace test_program {

[[noreturn]] inline void die(const char* program, const std::string& what) {
  std::fprintf(stderr, "%s: %s\n", program, what.c_str());
  std::exit(1);
}

/// The options the programs share, each followed by its value: --size WxH, --frames N and, where
/// `takes_out`, --out FILE (else an unknown option).
struct Options {
  int width = 160, height = 120, frames = 3;
  std::string out;
};

/// The options of argv; `own(option, value)` takes the program's other options and returns whether
/// it knew the option. An option nobody knows ends the program ("unknown option --x").
template <typename Own>
Options parseOptions(const char* program, int argc, char** argv, bool takes_out, Own own) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--size") std::sscanf(v.c_str(), "%dx%d", &o.width, &o.height);
    else if (a == "--frames") o.frames = std::atoi(v.c_str());
    else if (takes_out && a == "--out") o.out = v;
    else if (!own(a, v)) die(program, "unknown option " + a);
  }
  return o;
}

/// A compiled shader of `type`, or the program ended with the GLSL log.
inline GLuint compile(const char* program, GLenum type, const char* src) {
  try {
    return gl_common::compileShader(gl_common::linkedShaderCalls(), type, src, "test");
  } catch (const std::exception& e) {
    die(program, e.what());
  }
}

struct EglPbuffer {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLSurface surface = EGL_NO_SURFACE;
};

/// A surfaceless-platform RGBA8 + depth 24 pbuffer of width x height, current with an OpenGL
/// context made with `context_attributes` (`what` names that context in the error).
inline EglPbuffer makeCurrentPbuffer(const char* program, int width, int height, const EGLint* context_attributes,
                                     const char* what) {
  EglPbuffer p;
  p.display = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (p.display == EGL_NO_DISPLAY || !eglInitialize(p.display, nullptr, nullptr)) die(program, "no EGL display");
  const EGLint cfg_attrs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_RED_SIZE, 8,
                              EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE, 24, EGL_NONE};
  EGLConfig cfg;
  EGLint n = 0;
  if (!eglChooseConfig(p.display, cfg_attrs, &cfg, 1, &n) || n == 0) die(program, "no EGL config");
  eglBindAPI(EGL_OPENGL_API);
  const EGLint surf_attrs[] = {EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE};
  p.surface = eglCreatePbufferSurface(p.display, cfg, surf_attrs);
  EGLContext ctx = eglCreateContext(p.display, cfg, EGL_NO_CONTEXT, context_attributes);
  if (p.surface == EGL_NO_SURFACE || ctx == EGL_NO_CONTEXT) die(program, std::string("no EGL surface or ") + what);
  if (!eglMakeCurrent(p.display, p.surface, p.surface, ctx)) die(program, "eglMakeCurrent failed");
  return p;
}

}  // namespace test_program
}  // namespace viper
