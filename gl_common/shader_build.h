// Compiling GLSL shaders and linking programs with errors that name the shader and carry the
// GLSL log, through whichever GL entry points the program uses (libGL's exports or a loaded table).
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#define GL_GLCOREARB_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <initializer_list>
#include <string>

namespace viper {
namespace gl_common {

/// The GL functions compileShader() and linkProgram() call.
struct ShaderCalls {
  decltype(&::glCreateShader) CreateShader;
  decltype(&::glShaderSource) ShaderSource;
  decltype(&::glCompileShader) CompileShader;
  decltype(&::glGetShaderiv) GetShaderiv;
  decltype(&::glGetShaderInfoLog) GetShaderInfoLog;
  decltype(&::glDeleteShader) DeleteShader;
  decltype(&::glLinkProgram) LinkProgram;
  decltype(&::glGetProgramiv) GetProgramiv;
  decltype(&::glGetProgramInfoLog) GetProgramInfoLog;
};

/// The functions libGL exports (for a program that links libGL and calls it directly).
ShaderCalls linkedShaderCalls();

/// The same functions taken from a program's own table, any struct with members named
/// CreateShader, ShaderSource, ... (the names without the "gl" prefix).
template <typename GlTable>
ShaderCalls shaderCallsOf(const GlTable& gl) {
  return {gl.CreateShader, gl.ShaderSource,  gl.CompileShader, gl.GetShaderiv,      gl.GetShaderInfoLog,
          gl.DeleteShader, gl.LinkProgram,   gl.GetProgramiv,  gl.GetProgramInfoLog};
}

/// Creates and compiles a shader of `type` (GL_VERTEX_SHADER, GL_FRAGMENT_SHADER) from `source`.
/// On failure deletes it and throws std::runtime_error "compiling the <name> vertex shader failed:
/// <GLSL log>".
GLuint compileShader(const ShaderCalls& gl, GLenum type, const char* source, const std::string& name);

/// glLinkProgram on `program`, then glDeleteShader on each of `shaders` (attached shaders live on
/// with the program), then checks the link status. Throws std::runtime_error "linking the <name>
/// program failed: <GLSL log>".
void linkProgram(const ShaderCalls& gl, GLuint program, std::initializer_list<GLuint> shaders,
                 const std::string& name);

}  // namespace gl_common
}  // namespace viper
