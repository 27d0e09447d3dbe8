// Exported introspection entry points: a program the layer rewrote has two uniforms of the
// layer's (viper_draw_id, viper_alpha_test) that the program never declared. Every way a program
// can list its active uniforms answers as without them: the counts and the longest name leave
// them out, and active-uniform indices are the program's own, those after ours moved down (an
// index the program passes is turned into the GL's before the call, one the GL returns into the
// program's after it; ours answer GL_INVALID_INDEX).
#include "hooks.h"
#include "interceptor.h"

#include <vector>

using viper::capture::gl;
using viper::capture::Interceptor;

namespace {

// The uniforms the layer hides in `program` (empty: none, or a program the layer did not link).
struct Hidden {
  std::vector<GLuint> indices;  ///< the GL's indices of ours, ascending
  GLint max_length = 0;         ///< GL_ACTIVE_UNIFORM_MAX_LENGTH of the program's own
  bool any() const { return !indices.empty(); }
};

Hidden hiddenIn(GLuint program) {
  Hidden h;
  if (Interceptor* i = Interceptor::active()) i->hiddenUniforms(program, h.indices, h.max_length);
  return h;
}

// The program's index -> the GL's (an index past the program's last stays past the GL's last, so
// the GL reports the error the program would see).
GLuint toGl(const Hidden& h, GLuint index) {
  if (index == GL_INVALID_INDEX) return index;
  for (GLuint hidden : h.indices)
    if (hidden <= index) ++index;
  return index;
}

// The GL's index -> the program's (GL_INVALID_INDEX for one of ours).
GLuint toProgram(const Hidden& h, GLuint index) {
  if (index == GL_INVALID_INDEX) return index;
  GLuint below = 0;
  for (GLuint hidden : h.indices) {
    if (hidden == index) return GL_INVALID_INDEX;
    below += hidden < index;
  }
  return index - below;
}

// A count or a longest name the GL gave for the uniforms of `program`, as the program sees it.
void adjustUniformCount(const Hidden& h, GLenum pname, GLint* value) {
  if (!value || !h.any()) return;
  if (pname == GL_ACTIVE_UNIFORMS) *value -= static_cast<GLint>(h.indices.size());
  else if (pname == GL_ACTIVE_UNIFORM_MAX_LENGTH) *value = h.max_length;
}

}  // namespace

VIPER_EXPORT void glGetProgramiv(GLuint program, GLenum pname, GLint* params) {
  gl().GetProgramiv(program, pname, params);
  if (pname == GL_ACTIVE_UNIFORMS || pname == GL_ACTIVE_UNIFORM_MAX_LENGTH)
    adjustUniformCount(hiddenIn(program), pname, params);
}
// ARB_shader_objects: the same question of a program (or of a shader, which has no uniforms).
VIPER_EXPORT void glGetObjectParameterivARB(GLuint object, GLenum pname, GLint* params) {
  gl().GetObjectParameterivARB(object, pname, params);
  if (pname == GL_ACTIVE_UNIFORMS || pname == GL_ACTIVE_UNIFORM_MAX_LENGTH)
    adjustUniformCount(hiddenIn(object), pname, params);
}
VIPER_EXPORT void glGetActiveUniform(GLuint program, GLuint index, GLsizei buf_size, GLsizei* length, GLint* size,
                                     GLenum* type, GLchar* name) {
  gl().GetActiveUniform(program, toGl(hiddenIn(program), index), buf_size, length, size, type, name);
}
VIPER_EXPORT void glGetActiveUniformName(GLuint program, GLuint index, GLsizei buf_size, GLsizei* length,
                                         GLchar* name) {
  gl().GetActiveUniformName(program, toGl(hiddenIn(program), index), buf_size, length, name);
}
VIPER_EXPORT void glGetActiveUniformsiv(GLuint program, GLsizei count, const GLuint* indices, GLenum pname,
                                        GLint* params) {
  const Hidden h = hiddenIn(program);
  if (!h.any() || count <= 0 || !indices) return gl().GetActiveUniformsiv(program, count, indices, pname, params);
  std::vector<GLuint> mapped(indices, indices + count);
  for (GLuint& i : mapped) i = toGl(h, i);
  gl().GetActiveUniformsiv(program, count, mapped.data(), pname, params);
}
VIPER_EXPORT void glGetUniformIndices(GLuint program, GLsizei count, const GLchar* const* names, GLuint* indices) {
  gl().GetUniformIndices(program, count, names, indices);
  const Hidden h = hiddenIn(program);
  if (!h.any() || count <= 0 || !indices) return;
  for (GLsizei i = 0; i < count; ++i) indices[i] = toProgram(h, indices[i]);
}
VIPER_EXPORT void glGetActiveUniformBlockiv(GLuint program, GLuint block, GLenum pname, GLint* params) {
  const Hidden h = hiddenIn(program);
  if (!h.any() || pname != GL_UNIFORM_BLOCK_ACTIVE_UNIFORM_INDICES || !params)
    return gl().GetActiveUniformBlockiv(program, block, pname, params);
  GLint n = 0;
  gl().GetActiveUniformBlockiv(program, block, GL_UNIFORM_BLOCK_ACTIVE_UNIFORMS, &n);
  gl().GetActiveUniformBlockiv(program, block, pname, params);
  for (GLint i = 0; i < n; ++i)
    params[i] = static_cast<GLint>(toProgram(h, static_cast<GLuint>(params[i])));
}
// ARB_program_interface_query: the GL_UNIFORM interface, and the uniform indices a uniform block
// lists (GL_ACTIVE_VARIABLES).
VIPER_EXPORT void glGetProgramInterfaceiv(GLuint program, GLenum interface, GLenum pname, GLint* params) {
  gl().GetProgramInterfaceiv(program, interface, pname, params);
  if (interface != GL_UNIFORM || !params) return;
  const Hidden h = hiddenIn(program);
  if (!h.any()) return;
  if (pname == GL_ACTIVE_RESOURCES) *params -= static_cast<GLint>(h.indices.size());
  else if (pname == GL_MAX_NAME_LENGTH) *params = h.max_length;
}
VIPER_EXPORT GLuint glGetProgramResourceIndex(GLuint program, GLenum interface, const GLchar* name) {
  const GLuint index = gl().GetProgramResourceIndex(program, interface, name);
  return interface == GL_UNIFORM ? toProgram(hiddenIn(program), index) : index;
}
VIPER_EXPORT void glGetProgramResourceName(GLuint program, GLenum interface, GLuint index, GLsizei buf_size,
                                           GLsizei* length, GLchar* name) {
  if (interface == GL_UNIFORM) index = toGl(hiddenIn(program), index);
  gl().GetProgramResourceName(program, interface, index, buf_size, length, name);
}
VIPER_EXPORT void glGetProgramResourceiv(GLuint program, GLenum interface, GLuint index, GLsizei prop_count,
                                         const GLenum* props, GLsizei buf_size, GLsizei* length, GLint* params) {
  const Hidden h = hiddenIn(program);
  if (!h.any()) return gl().GetProgramResourceiv(program, interface, index, prop_count, props, buf_size, length, params);
  if (interface == GL_UNIFORM) index = toGl(h, index);
  gl().GetProgramResourceiv(program, interface, index, prop_count, props, buf_size, length, params);
  if (interface != GL_UNIFORM_BLOCK || !props || !params) return;
  // Each property gives one value, but GL_ACTIVE_VARIABLES, which gives GL_NUM_ACTIVE_VARIABLES.
  GLsizei at = 0;
  for (GLsizei p = 0; p < prop_count && at < buf_size; ++p) {
    if (props[p] != GL_ACTIVE_VARIABLES) {
      ++at;
      continue;
    }
    const GLenum count_prop = GL_NUM_ACTIVE_VARIABLES;
    GLint n = 0;
    gl().GetProgramResourceiv(program, interface, index, 1, &count_prop, 1, nullptr, &n);
    for (GLint k = 0; k < n && at < buf_size; ++k, ++at)
      params[at] = static_cast<GLint>(toProgram(h, static_cast<GLuint>(params[at])));
  }
}

// ARB_shader_objects' name of glGetActiveUniform (its handles are program names in Mesa).
extern "C" __attribute__((visibility("default"), alias("glGetActiveUniform"))) decltype(::glGetActiveUniform)
    glGetActiveUniformARB;

namespace viper {
namespace capture {

VIPER_NO_SANITIZE void* wrapperForIntrospection(const char* name) {
#define VIPER_ENTRY(f) VIPER_HOOK_ENTRY(f)
  static const HookEntry kEntries[] = {
      VIPER_ENTRY(glGetProgramiv),          VIPER_ENTRY(glGetObjectParameterivARB),
      VIPER_ENTRY(glGetActiveUniform),      VIPER_ENTRY(glGetActiveUniformName),
      VIPER_ENTRY(glGetActiveUniformsiv),   VIPER_ENTRY(glGetUniformIndices),
      VIPER_ENTRY(glGetActiveUniformBlockiv), VIPER_ENTRY(glGetProgramInterfaceiv),
      VIPER_ENTRY(glGetProgramResourceIndex), VIPER_ENTRY(glGetProgramResourceName),
      VIPER_ENTRY(glGetProgramResourceiv),  VIPER_ENTRY(glGetActiveUniformARB),
  };
#undef VIPER_ENTRY
  return findHook(kEntries, name);
}

}  // namespace capture
}  // namespace viper
