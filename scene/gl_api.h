// The OpenGL functions the test scene calls, as one table of function pointers filled either from
// the symbols libGL exports (direct linking) or through eglGetProcAddress, so a capture layer can be
// tested on both ways programs reach OpenGL.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#define GL_GLCOREARB_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <string>

namespace viper {
namespace scene {

// X(name) for every GL function used; the table member is the name without the "gl" prefix.
#define VIPER_SCENE_GL_FUNCTIONS(X)                                                                         \
  X(AttachShader) X(BindBuffer) X(BindVertexArray) X(BlendFunc) X(BufferData) X(Clear) X(ClearColor)       \
  X(CompileShader) X(CreateProgram) X(CreateShader) X(DeleteBuffers) X(DeleteProgram)          \
  X(DeleteShader) X(DeleteVertexArrays) X(DepthFunc) X(DepthMask) X(Disable) X(DrawElements) X(Enable)      \
  X(EnableVertexAttribArray) X(Finish) X(GenBuffers) X(GenVertexArrays) X(GetError) X(GetProgramInfoLog)    \
  X(GetProgramiv) X(GetShaderInfoLog) X(GetShaderiv) X(GetString) X(GetUniformLocation) X(LinkProgram)      \
  X(PixelStorei) X(ReadPixels) X(ShaderSource) X(Uniform3f) X(UniformMatrix4fv) X(UseProgram)              \
  X(VertexAttribPointer) X(Viewport)

/// How the table is filled.
enum class GlLoader {
  kDirect,   ///< addresses of the functions libGL exports (the program links libGL)
  kEglProc,  ///< eglGetProcAddress("glXxx") for every function
};

/// Function table; call as `gl.DrawElements(...)`.
struct GlApi {
#define VIPER_SCENE_GL_MEMBER(name) decltype(&::gl##name) name = nullptr;
  VIPER_SCENE_GL_FUNCTIONS(VIPER_SCENE_GL_MEMBER)
#undef VIPER_SCENE_GL_MEMBER
};

/// Fills the table. With kEglProc an EGL display must be initialised (a current context is not
/// needed). Throws std::runtime_error naming the first function that could not be found.
GlApi loadGlApi(GlLoader loader);

/// "direct" or "egl-proc".
std::string glLoaderName(GlLoader loader);

}  // namespace scene
}  // namespace viper
