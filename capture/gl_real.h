// The real OpenGL/EGL/GLX entry points, looked up past the interceptor's own exported symbols.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

namespace viper {
namespace capture {

// Every GL function the interceptor calls for real: (PFN type, name without the gl prefix).
#define VIPER_REAL_GL_FUNCTIONS(X)                                                        \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                  \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                                \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                    \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                          \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                                  \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                    \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                                      \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                  \
  X(PFNGLGETATTACHEDSHADERSPROC, GetAttachedShaders)                                      \
  X(PFNGLGETACTIVEUNIFORMPROC, GetActiveUniform)                                          \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                      \
  X(PFNGLGETATTRIBLOCATIONPROC, GetAttribLocation)                                        \
  X(PFNGLGETUNIFORMFVPROC, GetUniformfv)                                                  \
  X(PFNGLGETUNIFORMIVPROC, GetUniformiv)                                                  \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                                        \
  X(PFNGLBINDFRAGDATALOCATIONPROC, BindFragDataLocation)                                  \
  X(PFNGLTRANSFORMFEEDBACKVARYINGSPROC, TransformFeedbackVaryings)                        \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                            \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                            \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                      \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                                  \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                              \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                          \
  X(PFNGLGETRENDERBUFFERPARAMETERIVPROC, GetRenderbufferParameteriv)                      \
  X(PFNGLGETTEXLEVELPARAMETERIVPROC, GetTexLevelParameteriv)                              \
  X(PFNGLGETFRAMEBUFFERATTACHMENTPARAMETERIVPROC, GetFramebufferAttachmentParameteriv)    \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                                            \
  X(PFNGLDRAWBUFFERPROC, DrawBuffer)                                                      \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                                    \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                                      \
  X(PFNGLCLEARPROC, Clear)                                                                \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                                \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                                      \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                    \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                    \
  X(PFNGLISENABLEDPROC, IsEnabled)                                                        \
  X(PFNGLISENABLEDIPROC, IsEnabledi)                                                      \
  X(PFNGLENABLEPROC, Enable)                                                              \
  X(PFNGLDISABLEPROC, Disable)                                                            \
  X(PFNGLENABLEIPROC, Enablei)                                                            \
  X(PFNGLDISABLEIPROC, Disablei)                                                          \
  X(PFNGLBLENDFUNCPROC, BlendFunc)                                                        \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)                                        \
  X(PFNGLBLENDEQUATIONPROC, BlendEquation)                                                \
  X(PFNGLBLENDEQUATIONSEPARATEPROC, BlendEquationSeparate)                                \
  X(PFNGLBLENDFUNCSEPARATEIPROC, BlendFuncSeparatei)                                      \
  X(PFNGLBLENDEQUATIONIPROC, BlendEquationi)                                              \
  X(PFNGLCOLORMASKIPROC, ColorMaski)                                                      \
  X(PFNGLGETBOOLEANVPROC, GetBooleanv)                                                    \
  X(PFNGLGETBOOLEANI_VPROC, GetBooleani_v)                                                \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                                    \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                              \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                                    \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                                \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                                      \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                                \
  X(PFNGLTEXSTORAGE2DPROC, TexStorage2D)                                                  \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                                \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                                      \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                                      \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                              \
  X(PFNGLBUFFERDATAPROC, BufferData)                                                      \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                                                \
  X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                                          \
  X(PFNGLMAPBUFFERPROC, MapBuffer)                                                        \
  X(PFNGLMAPBUFFERRANGEPROC, MapBufferRange)                                              \
  X(PFNGLUNMAPBUFFERPROC, UnmapBuffer)                                                    \
  X(PFNGLCOPYBUFFERSUBDATAPROC, CopyBufferSubData)                                        \
  X(PFNGLNAMEDBUFFERDATAPROC, NamedBufferData)                                            \
  X(PFNGLNAMEDBUFFERSUBDATAPROC, NamedBufferSubData)                                      \
  X(PFNGLGETVERTEXATTRIBIVPROC, GetVertexAttribiv)                                        \
  X(PFNGLGETVERTEXATTRIBPOINTERVPROC, GetVertexAttribPointerv)                            \
  X(PFNGLGENTRANSFORMFEEDBACKSPROC, GenTransformFeedbacks)                                \
  X(PFNGLBINDTRANSFORMFEEDBACKPROC, BindTransformFeedback)                                \
  X(PFNGLBEGINTRANSFORMFEEDBACKPROC, BeginTransformFeedback)                              \
  X(PFNGLENDTRANSFORMFEEDBACKPROC, EndTransformFeedback)                                  \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                                      \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)                                                  \
  X(PFNGLDRAWELEMENTSBASEVERTEXPROC, DrawElementsBaseVertex)                              \
  X(PFNGLDRAWRANGEELEMENTSPROC, DrawRangeElements)                                        \
  X(PFNGLDRAWRANGEELEMENTSBASEVERTEXPROC, DrawRangeElementsBaseVertex)                    \
  X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)                                    \
  X(PFNGLDRAWELEMENTSINSTANCEDPROC, DrawElementsInstanced)                                \
  X(PFNGLDRAWELEMENTSINSTANCEDBASEVERTEXPROC, DrawElementsInstancedBaseVertex)                \
  X(PFNGLDRAWARRAYSINSTANCEDBASEINSTANCEPROC, DrawArraysInstancedBaseInstance)            \
  X(PFNGLDRAWELEMENTSINSTANCEDBASEINSTANCEPROC, DrawElementsInstancedBaseInstance)        \
  X(PFNGLDRAWELEMENTSINSTANCEDBASEVERTEXBASEINSTANCEPROC, DrawElementsInstancedBaseVertexBaseInstance) \
  X(PFNGLMULTIDRAWARRAYSPROC, MultiDrawArrays)                                            \
  X(PFNGLMULTIDRAWELEMENTSPROC, MultiDrawElements)                                        \
  X(PFNGLMULTIDRAWELEMENTSBASEVERTEXPROC, MultiDrawElementsBaseVertex)                    \
  X(PFNGLDRAWARRAYSINDIRECTPROC, DrawArraysIndirect)                                      \
  X(PFNGLDRAWELEMENTSINDIRECTPROC, DrawElementsIndirect)                                  \
  X(PFNGLMULTIDRAWARRAYSINDIRECTPROC, MultiDrawArraysIndirect)                            \
  X(PFNGLMULTIDRAWELEMENTSINDIRECTPROC, MultiDrawElementsIndirect)                        \
  X(PFNGLBUFFERSTORAGEPROC, BufferStorage)                                                \
  X(PFNGLNAMEDBUFFERSTORAGEPROC, NamedBufferStorage)                                      \
  X(PFNGLCLEARBUFFERIVPROC, ClearBufferiv)                                                \
  X(PFNGLCLEARBUFFERUIVPROC, ClearBufferuiv)                                              \
  X(PFNGLCLEARBUFFERFIPROC, ClearBufferfi)                                                \
  X(PFNGLGETUNIFORMINDICESPROC, GetUniformIndices)                                        \
  X(PFNGLGETACTIVEUNIFORMSIVPROC, GetActiveUniformsiv)                                    \
  X(PFNGLGETACTIVEUNIFORMBLOCKIVPROC, GetActiveUniformBlockiv)                            \
  X(PFNGLGETINTEGERI_VPROC, GetIntegeri_v)                                                \
  X(PFNGLGETINTEGER64I_VPROC, GetInteger64i_v)                                            \
  X(PFNGLPROGRAMBINARYPROC, ProgramBinary)                                                \
  X(PFNGLCOMPRESSEDTEXIMAGE2DPROC, CompressedTexImage2D)                                  \
  X(PFNGLCOMPRESSEDTEXSUBIMAGE2DPROC, CompressedTexSubImage2D)

/// Pointers to the real GL functions (libglvnd dispatch stubs, valid for EGL and GLX contexts).
struct RealGl {
#define VIPER_DECLARE_MEMBER(type, name) type name = nullptr;
  VIPER_REAL_GL_FUNCTIONS(VIPER_DECLARE_MEMBER)
#undef VIPER_DECLARE_MEMBER
};

/// The real GL table; filled on first use.
const RealGl& gl();

/// glGetIntegerv of one value, through the real GL.
inline GLint glInt(GLenum pname) {
  GLint v = 0;
  gl().GetIntegerv(pname, &v);
  return v;
}

/// A parameter of an attachment of the bound draw framebuffer, through the real GL.
inline GLint drawAttachmentParam(GLenum attachment, GLenum pname) {
  GLint v = 0;
  gl().GetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, attachment, pname, &v);
  return v;
}

/// The real dlsym (the interceptor interposes dlsym itself).
void* realDlsym(void* handle, const char* name);

/// A real EGL or GLX function by name, from libEGL.so.1 or libGLX.so.0/libGL.so.1; null if absent.
void* realEglFunction(const char* name);
void* realGlxFunction(const char* name);

}  // namespace capture
}  // namespace viper
