#include "shader_build.h"

#include <stdexcept>

namespace viper {
namespace gl_common {

ShaderCalls linkedShaderCalls() {
  return {&::glCreateShader, &::glShaderSource,  &::glCompileShader, &::glGetShaderiv,      &::glGetShaderInfoLog,
          &::glDeleteShader, &::glLinkProgram,   &::glGetProgramiv,  &::glGetProgramInfoLog};
}

GLuint compileShader(const ShaderCalls& gl, GLenum type, const char* source, const std::string& name) {
  const GLuint shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[4096] = {0};
    gl.GetShaderInfoLog(shader, sizeof(log), nullptr, log);
    gl.DeleteShader(shader);
    throw std::runtime_error("compiling the " + name + (type == GL_VERTEX_SHADER ? " vertex" : " fragment") +
                             " shader failed: " + log);
  }
  return shader;
}

void linkProgram(const ShaderCalls& gl, GLuint program, std::initializer_list<GLuint> shaders,
                 const std::string& name) {
  gl.LinkProgram(program);
  for (const GLuint shader : shaders) gl.DeleteShader(shader);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[4096] = {0};
    gl.GetProgramInfoLog(program, sizeof(log), nullptr, log);
    throw std::runtime_error("linking the " + name + " program failed: " + log);
  }
}

}  // namespace gl_common
}  // namespace viper
