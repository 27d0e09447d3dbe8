// Exported OpenGL entry points. Each forwards to the real driver, telling the interceptor first.
#include "hooks.h"
#include "interceptor.h"

#include <cstring>
#include <type_traits>
#include <vector>

using viper::capture::DrawCall;
using viper::capture::gl;
using viper::capture::Interceptor;

namespace {

// The draw a DrawCall describes, as an instanced draw from its base instance (GL 4.2): one
// instance of a split instanced draw, or one command of an indirect draw.
void issueInstanced(const DrawCall& c) {
  if (c.indexed)
    gl().DrawElementsInstancedBaseVertexBaseInstance(c.mode, c.count, c.index_type,
                                                     reinterpret_cast<const void*>(c.index_offset), c.instances,
                                                     c.base_vertex, c.base_instance);
  else
    gl().DrawArraysInstancedBaseInstance(c.mode, c.first, c.count, c.instances, c.base_instance);
}

template <typename F>
inline void draw(const DrawCall& call, F real) {
  Interceptor* i = Interceptor::active();
  if (!i) return real();
  if (i->splitsInstances(call)) {
    // Every instance its own draw id and record (Interceptor::splitsInstances says when this
    // draws exactly what the instanced call would).
    DrawCall one = call;
    one.instances = 1;
    for (GLsizei k = 0; k < call.instances; ++k) {
      one.base_instance = call.base_instance + static_cast<GLuint>(k);
      const bool recorded = i->beforeDraw(one);
      issueInstanced(one);
      if (recorded) i->afterDraw(one);
    }
    return;
  }
  const bool recorded = i->beforeDraw(call);
  real();
  if (!recorded) return;
  if (i->beginIdPass()) {  // a draw without a program: its ids from the same call again
    real();
    i->endIdPass();
  }
  i->afterDraw(call);
}

}  // namespace

VIPER_EXPORT void glShaderSource(GLuint shader, GLsizei count, const GLchar* const* string, const GLint* length) {
  if (Interceptor* i = Interceptor::active()) return i->shaderSource(shader, count, string, length);
  gl().ShaderSource(shader, count, string, length);
}
VIPER_EXPORT void glCompileShader(GLuint shader) {
  if (Interceptor* i = Interceptor::active()) return i->compileShader(shader);
  gl().CompileShader(shader);
}
VIPER_EXPORT void glLinkProgram(GLuint program) {
  if (Interceptor* i = Interceptor::active()) return i->linkProgram(program);
  gl().LinkProgram(program);
}
VIPER_EXPORT void glUseProgram(GLuint program) {
  gl().UseProgram(program);
  if (Interceptor* i = Interceptor::active()) i->useProgram(program);
}
VIPER_EXPORT void glTransformFeedbackVaryings(GLuint program, GLsizei count, const GLchar* const* varyings,
                                              GLenum mode) {
  gl().TransformFeedbackVaryings(program, count, varyings, mode);
  if (Interceptor* i = Interceptor::active()) i->transformFeedbackVaryings(program);
}
VIPER_EXPORT void glBindFramebuffer(GLenum target, GLuint framebuffer) {
  if (Interceptor* i = Interceptor::active()) return i->bindFramebuffer(target, framebuffer);
  gl().BindFramebuffer(target, framebuffer);
}
VIPER_EXPORT void glBlitFramebuffer(GLint src_x0, GLint src_y0, GLint src_x1, GLint src_y1, GLint dst_x0,
                                    GLint dst_y0, GLint dst_x1, GLint dst_y1, GLbitfield mask, GLenum filter) {
  if (Interceptor* i = Interceptor::active())
    i->blitFramebuffer(src_x0, src_y0, src_x1, src_y1, dst_x0, dst_y0, dst_x1, dst_y1, mask);
  gl().BlitFramebuffer(src_x0, src_y0, src_x1, src_y1, dst_x0, dst_y0, dst_x1, dst_y1, mask, filter);
}
VIPER_EXPORT void glDrawBuffer(GLenum buf) {
  if (Interceptor* i = Interceptor::active()) return i->drawBuffer(buf);
  gl().DrawBuffer(buf);
}
VIPER_EXPORT void glDrawBuffers(GLsizei n, const GLenum* bufs) {
  if (Interceptor* i = Interceptor::active()) return i->drawBuffers(n, bufs);
  gl().DrawBuffers(n, bufs);
}
VIPER_EXPORT void glReadBuffer(GLenum src) {
  if (Interceptor* i = Interceptor::active()) return i->readBuffer(src);
  gl().ReadBuffer(src);
}
VIPER_EXPORT void glClear(GLbitfield mask) {
  if (Interceptor* i = Interceptor::active()) return i->clear(mask);
  gl().Clear(mask);
}
VIPER_EXPORT void glClearBufferfv(GLenum buffer, GLint drawbuffer, const GLfloat* value) {
  gl().ClearBufferfv(buffer, drawbuffer, value);
  if (Interceptor* i = Interceptor::active()) i->clearBuffer(buffer, drawbuffer);
}
VIPER_EXPORT void glClearBufferiv(GLenum buffer, GLint drawbuffer, const GLint* value) {
  gl().ClearBufferiv(buffer, drawbuffer, value);
  if (Interceptor* i = Interceptor::active()) i->clearBuffer(buffer, drawbuffer);
}
VIPER_EXPORT void glClearBufferuiv(GLenum buffer, GLint drawbuffer, const GLuint* value) {
  gl().ClearBufferuiv(buffer, drawbuffer, value);
  if (Interceptor* i = Interceptor::active()) i->clearBuffer(buffer, drawbuffer);
}
VIPER_EXPORT void glClearBufferfi(GLenum buffer, GLint drawbuffer, GLfloat depth, GLint stencil) {
  gl().ClearBufferfi(buffer, drawbuffer, depth, stencil);
  if (Interceptor* i = Interceptor::active()) i->clearBuffer(buffer, drawbuffer);
}
VIPER_EXPORT void glProgramParameteri(GLuint program, GLenum pname, GLint value) {
  gl().ProgramParameteri(program, pname, value);
  if (Interceptor* i = Interceptor::active()) i->programParameter(program, pname, value);
}
VIPER_EXPORT void glProgramBinary(GLuint program, GLenum format, const void* binary, GLsizei length) {
  if (Interceptor* i = Interceptor::active()) return i->programBinary(program);
  gl().ProgramBinary(program, format, binary, length);
}
// Queries: what the window's default framebuffer answers where the program has it bound (ours
// stands in for it), and the program's own state where the layer changed the GL's.
namespace {

template <typename T>
T queryValue(GLint64 v) {
  if constexpr (std::is_same_v<T, GLboolean>) return v != 0 ? GL_TRUE : GL_FALSE;
  else return static_cast<T>(v);
}

template <typename T, typename F>
void query(GLenum pname, T* data, F real) {
  Interceptor* i = Interceptor::active();
  if (!i) return real();
  const bool window = i->beginWindowQuery(pname);
  real();
  if (window) i->endWindowQuery();
  GLint64 v = 0;
  if (data && i->overrideQuery(pname, v)) *data = queryValue<T>(v);
}

template <typename F>
auto framebufferQuery(GLenum target, F real) {
  Interceptor* i = Interceptor::active();
  const bool window = i && i->beginWindowFramebufferQuery(target);
  struct Restore {
    Interceptor* i;
    ~Restore() { if (i) i->endWindowQuery(); }
  } restore{window ? i : nullptr};
  return real();
}

}  // namespace

VIPER_EXPORT void glGetIntegerv(GLenum pname, GLint* data) {
  query(pname, data, [&] { gl().GetIntegerv(pname, data); });
}
VIPER_EXPORT void glGetBooleanv(GLenum pname, GLboolean* data) {
  query(pname, data, [&] { gl().GetBooleanv(pname, data); });
}
VIPER_EXPORT void glGetFloatv(GLenum pname, GLfloat* data) {
  query(pname, data, [&] { gl().GetFloatv(pname, data); });
}
VIPER_EXPORT void glGetDoublev(GLenum pname, GLdouble* data) {
  query(pname, data, [&] { gl().GetDoublev(pname, data); });
}
VIPER_EXPORT void glGetInteger64v(GLenum pname, GLint64* data) {
  query(pname, data, [&] { gl().GetInteger64v(pname, data); });
}
VIPER_EXPORT void glGetFramebufferAttachmentParameteriv(GLenum target, GLenum attachment, GLenum pname,
                                                        GLint* params) {
  framebufferQuery(target, [&] { gl().GetFramebufferAttachmentParameteriv(target, attachment, pname, params); });
}
VIPER_EXPORT void glGetFramebufferParameteriv(GLenum target, GLenum pname, GLint* params) {
  framebufferQuery(target, [&] { gl().GetFramebufferParameteriv(target, pname, params); });
}
VIPER_EXPORT GLenum glCheckFramebufferStatus(GLenum target) {
  return framebufferQuery(target, [&] { return gl().CheckFramebufferStatus(target); });
}
VIPER_EXPORT void glDeleteFramebuffers(GLsizei n, const GLuint* framebuffers) {
  gl().DeleteFramebuffers(n, framebuffers);
  if (Interceptor* i = Interceptor::active()) i->framebuffersDeleted(n, framebuffers);
}
VIPER_EXPORT void glEnable(GLenum cap) {
  gl().Enable(cap);
  if (cap == GL_BLEND)
    if (Interceptor* i = Interceptor::active()) i->blendStateChanged(true, true);
}
VIPER_EXPORT void glDisable(GLenum cap) {
  gl().Disable(cap);
  if (cap == GL_BLEND)
    if (Interceptor* i = Interceptor::active()) i->blendStateChanged(true, false);
}
VIPER_EXPORT void glEnablei(GLenum cap, GLuint index) {
  gl().Enablei(cap, index);
  if (cap == GL_BLEND)
    if (Interceptor* i = Interceptor::active()) i->blendStateChanged(index == 0, true);
}
VIPER_EXPORT void glDisablei(GLenum cap, GLuint index) {
  gl().Disablei(cap, index);
  if (cap == GL_BLEND)
    if (Interceptor* i = Interceptor::active()) i->blendStateChanged(index == 0, false);
}
VIPER_EXPORT void glColorMask(GLboolean r, GLboolean g, GLboolean b, GLboolean a) {
  gl().ColorMask(r, g, b, a);
  if (Interceptor* i = Interceptor::active()) i->colorMaskChanged();
}
VIPER_EXPORT void glBlendFunc(GLenum s, GLenum d) {
  gl().BlendFunc(s, d);
  if (Interceptor* i = Interceptor::active()) i->blendStateChanged(false, false);
}
VIPER_EXPORT void glBlendFuncSeparate(GLenum sr, GLenum dr, GLenum sa, GLenum da) {
  gl().BlendFuncSeparate(sr, dr, sa, da);
  if (Interceptor* i = Interceptor::active()) i->blendStateChanged(false, false);
}
VIPER_EXPORT void glBlendEquation(GLenum mode) {
  gl().BlendEquation(mode);
  if (Interceptor* i = Interceptor::active()) i->blendStateChanged(false, false);
}
VIPER_EXPORT void glBlendEquationSeparate(GLenum rgb, GLenum alpha) {
  gl().BlendEquationSeparate(rgb, alpha);
  if (Interceptor* i = Interceptor::active()) i->blendStateChanged(false, false);
}
VIPER_EXPORT void glBufferData(GLenum target, GLsizeiptr size, const void* data, GLenum usage) {
  gl().BufferData(target, size, data, usage);
  if (Interceptor* i = Interceptor::active()) i->bufferData(target, 0, size, data);
}
VIPER_EXPORT void glBufferSubData(GLenum target, GLintptr offset, GLsizeiptr size, const void* data) {
  gl().BufferSubData(target, offset, size, data);
  if (Interceptor* i = Interceptor::active()) i->bufferSubData(target, 0, offset, size, data);
}
VIPER_EXPORT void glBufferStorage(GLenum target, GLsizeiptr size, const void* data, GLbitfield flags) {
  gl().BufferStorage(target, size, data, flags);
  if (Interceptor* i = Interceptor::active()) i->bufferStorage(target, 0, size, data);
}
VIPER_EXPORT void glNamedBufferStorage(GLuint buffer, GLsizeiptr size, const void* data, GLbitfield flags) {
  gl().NamedBufferStorage(buffer, size, data, flags);
  if (Interceptor* i = Interceptor::active()) i->bufferStorage(0, buffer, size, data);
}
VIPER_EXPORT void glNamedBufferData(GLuint buffer, GLsizeiptr size, const void* data, GLenum usage) {
  gl().NamedBufferData(buffer, size, data, usage);
  if (Interceptor* i = Interceptor::active()) i->bufferData(0, buffer, size, data);
}
VIPER_EXPORT void glNamedBufferSubData(GLuint buffer, GLintptr offset, GLsizeiptr size, const void* data) {
  gl().NamedBufferSubData(buffer, offset, size, data);
  if (Interceptor* i = Interceptor::active()) i->bufferSubData(0, buffer, offset, size, data);
}
VIPER_EXPORT void* glMapBuffer(GLenum target, GLenum access) {
  void* p = gl().MapBuffer(target, access);
  if (Interceptor* i = Interceptor::active())
    i->mapped(target, p, 0, -1, access == GL_READ_ONLY ? GL_MAP_READ_BIT : GL_MAP_WRITE_BIT);
  return p;
}
VIPER_EXPORT void* glMapBufferRange(GLenum target, GLintptr offset, GLsizeiptr length, GLbitfield access) {
  void* p = gl().MapBufferRange(target, offset, length, access);
  if (Interceptor* i = Interceptor::active()) i->mapped(target, p, offset, length, access);
  return p;
}
VIPER_EXPORT GLboolean glUnmapBuffer(GLenum target) {
  if (Interceptor* i = Interceptor::active()) i->beforeUnmap(target);
  return gl().UnmapBuffer(target);
}
VIPER_EXPORT void glCopyBufferSubData(GLenum rt, GLenum wt, GLintptr ro, GLintptr wo, GLsizeiptr size) {
  gl().CopyBufferSubData(rt, wt, ro, wo, size);
  if (Interceptor* i = Interceptor::active()) i->copyBufferSubData(rt, wt, ro, wo, size);
}
VIPER_EXPORT void glDeleteBuffers(GLsizei n, const GLuint* buffers) {
  if (Interceptor* i = Interceptor::active()) i->deleteBuffers(n, buffers);
  gl().DeleteBuffers(n, buffers);
}
VIPER_EXPORT void glActiveTexture(GLenum texture) {
  gl().ActiveTexture(texture);
  if (Interceptor* i = Interceptor::active()) i->activeTexture(texture);
}
VIPER_EXPORT void glBindTexture(GLenum target, GLuint texture) {
  gl().BindTexture(target, texture);
  if (Interceptor* i = Interceptor::active()) i->bindTexture(target, texture);
}
VIPER_EXPORT void glTexImage2D(GLenum target, GLint level, GLint internalformat, GLsizei width, GLsizei height,
                               GLint border, GLenum format, GLenum type, const void* pixels) {
  gl().TexImage2D(target, level, internalformat, width, height, border, format, type, pixels);
  if (Interceptor* i = Interceptor::active()) i->texImage(target, level, width, height, format, type, pixels, false, 0, 0);
}
VIPER_EXPORT void glTexSubImage2D(GLenum target, GLint level, GLint x, GLint y, GLsizei width, GLsizei height,
                                  GLenum format, GLenum type, const void* pixels) {
  gl().TexSubImage2D(target, level, x, y, width, height, format, type, pixels);
  if (Interceptor* i = Interceptor::active()) i->texImage(target, level, width, height, format, type, pixels, true, x, y);
}
VIPER_EXPORT void glTexStorage2D(GLenum target, GLsizei levels, GLenum internalformat, GLsizei width, GLsizei height) {
  gl().TexStorage2D(target, levels, internalformat, width, height);
  if (Interceptor* i = Interceptor::active())
    i->texImage(target, 0, width, height, internalformat, 0, nullptr, false, 0, 0);
}
VIPER_EXPORT void glCompressedTexImage2D(GLenum target, GLint level, GLenum internalformat, GLsizei width,
                                         GLsizei height, GLint border, GLsizei size, const void* data) {
  gl().CompressedTexImage2D(target, level, internalformat, width, height, border, size, data);
  if (Interceptor* i = Interceptor::active())
    i->compressedTexImage(target, level, width, height, internalformat, size, data, false, 0, 0);
}
VIPER_EXPORT void glCompressedTexSubImage2D(GLenum target, GLint level, GLint x, GLint y, GLsizei width,
                                            GLsizei height, GLenum format, GLsizei size, const void* data) {
  gl().CompressedTexSubImage2D(target, level, x, y, width, height, format, size, data);
  if (Interceptor* i = Interceptor::active()) i->compressedTexImage(target, level, width, height, format, size, data, true, x, y);
}
VIPER_EXPORT void glDeleteTextures(GLsizei n, const GLuint* textures) {
  if (Interceptor* i = Interceptor::active()) i->deleteTextures(n, textures);
  gl().DeleteTextures(n, textures);
}

// Draw calls.
VIPER_EXPORT void glDrawArrays(GLenum mode, GLint first, GLsizei count) {
  DrawCall c;
  c.mode = mode, c.first = first, c.count = count;
  draw(c, [&] { gl().DrawArrays(mode, first, count); });
}
VIPER_EXPORT void glDrawArraysInstanced(GLenum mode, GLint first, GLsizei count, GLsizei instances) {
  DrawCall c;
  c.mode = mode, c.first = first, c.count = count, c.instances = instances;
  draw(c, [&] { gl().DrawArraysInstanced(mode, first, count, instances); });
}

namespace {
DrawCall indexedCall(GLenum mode, GLsizei count, GLenum type, const void* indices, GLint base_vertex,
                     GLsizei instances) {
  DrawCall c;
  c.mode = mode, c.count = count, c.indexed = true, c.index_type = type;
  c.index_offset = reinterpret_cast<size_t>(indices), c.base_vertex = base_vertex, c.instances = instances;
  return c;
}
}  // namespace

VIPER_EXPORT void glDrawArraysInstancedBaseInstance(GLenum mode, GLint first, GLsizei count, GLsizei instances,
                                                    GLuint base_instance) {
  DrawCall c;
  c.mode = mode, c.first = first, c.count = count, c.instances = instances, c.base_instance = base_instance;
  draw(c, [&] { gl().DrawArraysInstancedBaseInstance(mode, first, count, instances, base_instance); });
}
VIPER_EXPORT void glDrawElements(GLenum mode, GLsizei count, GLenum type, const void* indices) {
  draw(indexedCall(mode, count, type, indices, 0, 1), [&] { gl().DrawElements(mode, count, type, indices); });
}
VIPER_EXPORT void glDrawElementsBaseVertex(GLenum mode, GLsizei count, GLenum type, const void* indices,
                                           GLint base) {
  draw(indexedCall(mode, count, type, indices, base, 1),
       [&] { gl().DrawElementsBaseVertex(mode, count, type, indices, base); });
}
VIPER_EXPORT void glDrawRangeElements(GLenum mode, GLuint start, GLuint end, GLsizei count, GLenum type,
                                      const void* indices) {
  draw(indexedCall(mode, count, type, indices, 0, 1),
       [&] { gl().DrawRangeElements(mode, start, end, count, type, indices); });
}
VIPER_EXPORT void glDrawRangeElementsBaseVertex(GLenum mode, GLuint start, GLuint end, GLsizei count, GLenum type,
                                                const void* indices, GLint base) {
  draw(indexedCall(mode, count, type, indices, base, 1),
       [&] { gl().DrawRangeElementsBaseVertex(mode, start, end, count, type, indices, base); });
}
VIPER_EXPORT void glDrawElementsInstanced(GLenum mode, GLsizei count, GLenum type, const void* indices,
                                          GLsizei instances) {
  draw(indexedCall(mode, count, type, indices, 0, instances),
       [&] { gl().DrawElementsInstanced(mode, count, type, indices, instances); });
}
VIPER_EXPORT void glDrawElementsInstancedBaseVertex(GLenum mode, GLsizei count, GLenum type, const void* indices,
                                                    GLsizei instances, GLint base) {
  draw(indexedCall(mode, count, type, indices, base, instances),
       [&] { gl().DrawElementsInstancedBaseVertex(mode, count, type, indices, instances, base); });
}
VIPER_EXPORT void glDrawElementsInstancedBaseInstance(GLenum mode, GLsizei count, GLenum type, const void* indices,
                                                      GLsizei instances, GLuint base_instance) {
  DrawCall c = indexedCall(mode, count, type, indices, 0, instances);
  c.base_instance = base_instance;
  draw(c, [&] { gl().DrawElementsInstancedBaseInstance(mode, count, type, indices, instances, base_instance); });
}
VIPER_EXPORT void glDrawElementsInstancedBaseVertexBaseInstance(GLenum mode, GLsizei count, GLenum type,
                                                                const void* indices, GLsizei instances, GLint base,
                                                                GLuint base_instance) {
  DrawCall c = indexedCall(mode, count, type, indices, base, instances);
  c.base_instance = base_instance;
  draw(c, [&] {
    gl().DrawElementsInstancedBaseVertexBaseInstance(mode, count, type, indices, instances, base, base_instance);
  });
}

// Multi-draws and indirect draws, as the single draws they stand for (Interceptor::decomposesMultiDraw).
namespace {

size_t indexSize(GLenum type) { return type == GL_UNSIGNED_BYTE ? 1 : type == GL_UNSIGNED_SHORT ? 2 : 4; }

// Commands of an indirect draw: {count, instances, first, base instance} or {count, instances,
// first index, base vertex, base instance}, `stride` bytes apart (0: packed).
bool indirectCalls(Interceptor& i, GLenum mode, bool indexed, GLenum type, const void* indirect, GLsizei drawcount,
                   GLsizei stride, std::vector<DrawCall>& calls) {
  const size_t size = indexed ? 20 : 16;
  const size_t step = stride ? static_cast<size_t>(stride) : size;
  for (GLsizei k = 0; k < drawcount; ++k) {
    GLuint cmd[5] = {0, 0, 0, 0, 0};
    if (!i.readIndirect(reinterpret_cast<size_t>(indirect) + k * step, cmd, size)) return false;
    DrawCall c;
    c.mode = mode, c.count = static_cast<GLsizei>(cmd[0]), c.instances = static_cast<GLsizei>(cmd[1]);
    if (indexed) {
      c.indexed = true, c.index_type = type, c.index_offset = cmd[2] * indexSize(type);
      c.base_vertex = static_cast<GLint>(cmd[3]), c.base_instance = cmd[4];
    } else {
      c.first = static_cast<GLint>(cmd[2]), c.base_instance = cmd[3];
    }
    calls.push_back(c);
  }
  return true;
}

template <typename F>
void indirectDraw(const char* what, GLenum mode, bool indexed, GLenum type, const void* indirect, GLsizei drawcount,
                  GLsizei stride, F real) {
  Interceptor* i = Interceptor::active();
  std::vector<DrawCall> calls;
  if (!i) return real();
  if (!i->decomposesMultiDraw() || !indirectCalls(*i, mode, indexed, type, indirect, drawcount, stride, calls)) {
    i->beforeUndecomposedDraw(what);
    return real();
  }
  for (const DrawCall& c : calls)
    if (c.instances > 0) draw(c, [&] { issueInstanced(c); });
}

}  // namespace

VIPER_EXPORT void glMultiDrawArrays(GLenum mode, const GLint* first, const GLsizei* count, GLsizei drawcount) {
  Interceptor* i = Interceptor::active();
  if (!i || !i->decomposesMultiDraw()) {
    if (i) i->beforeUndecomposedDraw("glMultiDrawArrays");
    return gl().MultiDrawArrays(mode, first, count, drawcount);
  }
  for (GLsizei k = 0; k < drawcount; ++k) glDrawArrays(mode, first[k], count[k]);
}
VIPER_EXPORT void glMultiDrawElementsBaseVertex(GLenum mode, const GLsizei* count, GLenum type,
                                                const void* const* indices, GLsizei drawcount, const GLint* base) {
  Interceptor* i = Interceptor::active();
  if (!i || !i->decomposesMultiDraw()) {
    if (i) i->beforeUndecomposedDraw("glMultiDrawElements");
    return base ? gl().MultiDrawElementsBaseVertex(mode, count, type, indices, drawcount, base)
                : gl().MultiDrawElements(mode, count, type, indices, drawcount);
  }
  for (GLsizei k = 0; k < drawcount; ++k) glDrawElementsBaseVertex(mode, count[k], type, indices[k], base ? base[k] : 0);
}
VIPER_EXPORT void glMultiDrawElements(GLenum mode, const GLsizei* count, GLenum type, const void* const* indices,
                                      GLsizei drawcount) {
  glMultiDrawElementsBaseVertex(mode, count, type, indices, drawcount, nullptr);
}
VIPER_EXPORT void glDrawArraysIndirect(GLenum mode, const void* indirect) {
  indirectDraw("glDrawArraysIndirect", mode, false, 0, indirect, 1, 0, [&] { gl().DrawArraysIndirect(mode, indirect); });
}
VIPER_EXPORT void glDrawElementsIndirect(GLenum mode, GLenum type, const void* indirect) {
  indirectDraw("glDrawElementsIndirect", mode, true, type, indirect, 1, 0,
               [&] { gl().DrawElementsIndirect(mode, type, indirect); });
}
VIPER_EXPORT void glMultiDrawArraysIndirect(GLenum mode, const void* indirect, GLsizei drawcount, GLsizei stride) {
  indirectDraw("glMultiDrawArraysIndirect", mode, false, 0, indirect, drawcount, stride,
               [&] { gl().MultiDrawArraysIndirect(mode, indirect, drawcount, stride); });
}
VIPER_EXPORT void glMultiDrawElementsIndirect(GLenum mode, GLenum type, const void* indirect, GLsizei drawcount,
                                              GLsizei stride) {
  indirectDraw("glMultiDrawElementsIndirect", mode, true, type, indirect, drawcount, stride,
               [&] { gl().MultiDrawElementsIndirect(mode, type, indirect, drawcount, stride); });
}

// The extension names of the functions above (ARB, EXT and vendor names that the GL registry
// gives as aliases of the core ones, or that drivers implement as the same function): the same
// wrappers, so a program that calls the extension name is seen as one that calls the core name
// (a framebuffer bound with glBindFramebufferEXT reached the real window before). Exported under
// those names, and found under them by glXGetProcAddress, eglGetProcAddress and dlsym (wrapperFor).
#define VIPER_GL_ALIASES(X) \
  X(glShaderSourceARB, glShaderSource)\
  X(glProgramParameteriARB, glProgramParameteri)\
  X(glProgramParameteriEXT, glProgramParameteri)\
  X(glCompileShaderARB, glCompileShader)\
  X(glLinkProgramARB, glLinkProgram)\
  X(glUseProgramObjectARB, glUseProgram)\
  X(glTransformFeedbackVaryingsEXT, glTransformFeedbackVaryings)\
  X(glBindFramebufferEXT, glBindFramebuffer)\
  X(glDeleteFramebuffersEXT, glDeleteFramebuffers)\
  X(glBlitFramebufferEXT, glBlitFramebuffer)\
  X(glCheckFramebufferStatusEXT, glCheckFramebufferStatus)\
  X(glGetFramebufferAttachmentParameterivEXT, glGetFramebufferAttachmentParameteriv)\
  X(glDrawBuffersARB, glDrawBuffers)\
  X(glDrawBuffersATI, glDrawBuffers)\
  X(glDrawBuffersEXT, glDrawBuffers)\
  X(glEnableIndexedEXT, glEnablei)\
  X(glEnableiEXT, glEnablei)\
  X(glDisableIndexedEXT, glDisablei)\
  X(glDisableiEXT, glDisablei)\
  X(glBlendFuncSeparateEXT, glBlendFuncSeparate)\
  X(glBlendFuncSeparateINGR, glBlendFuncSeparate)\
  X(glBlendEquationEXT, glBlendEquation)\
  X(glBlendEquationSeparateEXT, glBlendEquationSeparate)\
  X(glBlendEquationSeparateATI, glBlendEquationSeparate)\
  X(glBufferDataARB, glBufferData)\
  X(glBufferSubDataARB, glBufferSubData)\
  X(glMapBufferARB, glMapBuffer)\
  X(glUnmapBufferARB, glUnmapBuffer)\
  X(glDeleteBuffersARB, glDeleteBuffers)\
  X(glActiveTextureARB, glActiveTexture)\
  X(glBindTextureEXT, glBindTexture)\
  X(glDeleteTexturesEXT, glDeleteTextures)\
  X(glTexSubImage2DEXT, glTexSubImage2D)\
  X(glTexStorage2DEXT, glTexStorage2D)\
  X(glCompressedTexImage2DARB, glCompressedTexImage2D)\
  X(glCompressedTexSubImage2DARB, glCompressedTexSubImage2D)\
  X(glDrawArraysEXT, glDrawArrays)\
  X(glDrawArraysInstancedARB, glDrawArraysInstanced)\
  X(glDrawArraysInstancedEXT, glDrawArraysInstanced)\
  X(glDrawElementsInstancedARB, glDrawElementsInstanced)\
  X(glDrawElementsInstancedEXT, glDrawElementsInstanced)\
  X(glDrawRangeElementsEXT, glDrawRangeElements)\
  X(glDrawElementsBaseVertexEXT, glDrawElementsBaseVertex)\
  X(glMultiDrawArraysEXT, glMultiDrawArrays)\
  X(glMultiDrawElementsEXT, glMultiDrawElements)\
  X(glMultiDrawArraysIndirectAMD, glMultiDrawArraysIndirect)\
  X(glMultiDrawElementsIndirectAMD, glMultiDrawElementsIndirect)

#define VIPER_DEFINE_ALIAS(alias_name, core)                                                       \
  extern "C" __attribute__((visibility("default"), alias(#core))) decltype(::core) alias_name;
VIPER_GL_ALIASES(VIPER_DEFINE_ALIAS)
#undef VIPER_DEFINE_ALIAS

namespace viper {
namespace capture {

VIPER_NO_SANITIZE void* wrapperForWinsys(const char* name);
VIPER_NO_SANITIZE void* wrapperForLegacy(const char* name);
VIPER_NO_SANITIZE void* wrapperForImmediate(const char* name);
VIPER_NO_SANITIZE void* wrapperForIntrospection(const char* name);

VIPER_NO_SANITIZE void* wrapperFor(const char* name) {
  if (!name) return nullptr;
#define VIPER_ENTRY(f) VIPER_HOOK_ENTRY(f)
  static const HookEntry kEntries[] = {
      VIPER_ENTRY(glShaderSource), VIPER_ENTRY(glCompileShader), VIPER_ENTRY(glLinkProgram),
      VIPER_ENTRY(glUseProgram), VIPER_ENTRY(glTransformFeedbackVaryings), VIPER_ENTRY(glBindFramebuffer),
      VIPER_ENTRY(glBlitFramebuffer), VIPER_ENTRY(glDrawBuffer), VIPER_ENTRY(glDrawBuffers), VIPER_ENTRY(glReadBuffer),
      VIPER_ENTRY(glClear),
      VIPER_ENTRY(glGetIntegerv), VIPER_ENTRY(glGetBooleanv), VIPER_ENTRY(glGetFloatv), VIPER_ENTRY(glGetDoublev),
      VIPER_ENTRY(glGetInteger64v), VIPER_ENTRY(glGetFramebufferAttachmentParameteriv),
      VIPER_ENTRY(glGetFramebufferParameteriv), VIPER_ENTRY(glCheckFramebufferStatus),
      VIPER_ENTRY(glDeleteFramebuffers), VIPER_ENTRY(glColorMask), VIPER_ENTRY(glEnable), VIPER_ENTRY(glDisable), VIPER_ENTRY(glEnablei),
      VIPER_ENTRY(glDisablei), VIPER_ENTRY(glBlendFunc), VIPER_ENTRY(glBlendFuncSeparate),
      VIPER_ENTRY(glBlendEquation), VIPER_ENTRY(glBlendEquationSeparate), VIPER_ENTRY(glBufferData),
      VIPER_ENTRY(glBufferSubData), VIPER_ENTRY(glNamedBufferData), VIPER_ENTRY(glNamedBufferSubData),
      VIPER_ENTRY(glMapBuffer), VIPER_ENTRY(glMapBufferRange), VIPER_ENTRY(glUnmapBuffer),
      VIPER_ENTRY(glCopyBufferSubData), VIPER_ENTRY(glDeleteBuffers), VIPER_ENTRY(glActiveTexture),
      VIPER_ENTRY(glBindTexture), VIPER_ENTRY(glTexImage2D), VIPER_ENTRY(glTexSubImage2D),
      VIPER_ENTRY(glTexStorage2D), VIPER_ENTRY(glDeleteTextures), VIPER_ENTRY(glDrawArrays),
      VIPER_ENTRY(glDrawArraysInstanced), VIPER_ENTRY(glDrawElements), VIPER_ENTRY(glDrawElementsBaseVertex),
      VIPER_ENTRY(glDrawRangeElements), VIPER_ENTRY(glDrawRangeElementsBaseVertex),
      VIPER_ENTRY(glDrawElementsInstanced), VIPER_ENTRY(glDrawElementsInstancedBaseVertex),
      VIPER_ENTRY(glDrawArraysInstancedBaseInstance), VIPER_ENTRY(glDrawElementsInstancedBaseInstance),
      VIPER_ENTRY(glDrawElementsInstancedBaseVertexBaseInstance), VIPER_ENTRY(glBufferStorage),
      VIPER_ENTRY(glNamedBufferStorage), VIPER_ENTRY(glClearBufferfv), VIPER_ENTRY(glClearBufferiv),
      VIPER_ENTRY(glClearBufferuiv), VIPER_ENTRY(glClearBufferfi), VIPER_ENTRY(glProgramBinary), VIPER_ENTRY(glProgramParameteri),
      VIPER_ENTRY(glCompressedTexImage2D), VIPER_ENTRY(glCompressedTexSubImage2D),
      VIPER_ENTRY(glMultiDrawArrays), VIPER_ENTRY(glMultiDrawElements), VIPER_ENTRY(glMultiDrawElementsBaseVertex),
      VIPER_ENTRY(glDrawArraysIndirect), VIPER_ENTRY(glDrawElementsIndirect), VIPER_ENTRY(glMultiDrawArraysIndirect),
      VIPER_ENTRY(glMultiDrawElementsIndirect),
#define VIPER_ALIAS_ENTRY(alias_name, core) ::viper::capture::HookEntry{#alias_name, reinterpret_cast<void*>(&::core)},
      VIPER_GL_ALIASES(VIPER_ALIAS_ENTRY)
#undef VIPER_ALIAS_ENTRY
  };
#undef VIPER_ENTRY
  if (name[0] == 'g' && name[1] == 'l' && name[2] != 'X') {
    if (void* fn = findHook(kEntries, name)) return fn;
    if (void* fn = wrapperForLegacy(name)) return fn;
    if (void* fn = wrapperForIntrospection(name)) return fn;
    return wrapperForImmediate(name);
  }
  return wrapperForWinsys(name);
}

}  // namespace capture
}  // namespace viper
