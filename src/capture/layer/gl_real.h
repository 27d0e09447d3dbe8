// The real OpenGL/EGL/GLX entry points, looked up past the interceptor's own exported symbols.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

// The fixed-function (compatibility profile) entry points and enums the core header lacks.
typedef void (*PFNVIPERMATRIXMODEPROC)(GLenum mode);
typedef void (*PFNVIPERVOIDPROC)(void);
typedef void (*PFNVIPERMATRIXFPROC)(const GLfloat* m);
typedef void (*PFNVIPERMATRIXDPROC)(const GLdouble* m);
typedef void (*PFNVIPERXYZFPROC)(GLfloat x, GLfloat y, GLfloat z);
typedef void (*PFNVIPERXYZDPROC)(GLdouble x, GLdouble y, GLdouble z);
typedef void (*PFNVIPERROTATEFPROC)(GLfloat angle, GLfloat x, GLfloat y, GLfloat z);
typedef void (*PFNVIPERROTATEDPROC)(GLdouble angle, GLdouble x, GLdouble y, GLdouble z);
typedef void (*PFNVIPERACCUMPROC)(GLenum op, GLfloat value);
typedef void (*PFNVIPERBEGINPROC)(GLenum mode);
typedef void (*PFNVIPERCALLLISTPROC)(GLuint list);
typedef void (*PFNVIPERCALLLISTSPROC)(GLsizei n, GLenum type, const void* lists);
typedef void (*PFNVIPERNEWLISTPROC)(GLuint list, GLenum mode);
typedef void (*PFNVIPERGETOBJECTPARAMETERIVARBPROC)(GLuint object, GLenum pname, GLint* params);
typedef void (*PFNVIPERVERTEX2SPROC)(GLshort x, GLshort y);
typedef void (*PFNVIPERVERTEX2SVPROC)(const GLshort* v);
typedef void (*PFNVIPERVERTEX2IPROC)(GLint x, GLint y);
typedef void (*PFNVIPERVERTEX2IVPROC)(const GLint* v);
typedef void (*PFNVIPERVERTEX2FPROC)(GLfloat x, GLfloat y);
typedef void (*PFNVIPERVERTEX2FVPROC)(const GLfloat* v);
typedef void (*PFNVIPERVERTEX2DPROC)(GLdouble x, GLdouble y);
typedef void (*PFNVIPERVERTEX2DVPROC)(const GLdouble* v);
typedef void (*PFNVIPERVERTEX3SPROC)(GLshort x, GLshort y, GLshort z);
typedef void (*PFNVIPERVERTEX3SVPROC)(const GLshort* v);
typedef void (*PFNVIPERVERTEX3IPROC)(GLint x, GLint y, GLint z);
typedef void (*PFNVIPERVERTEX3IVPROC)(const GLint* v);
typedef void (*PFNVIPERVERTEX3FPROC)(GLfloat x, GLfloat y, GLfloat z);
typedef void (*PFNVIPERVERTEX3FVPROC)(const GLfloat* v);
typedef void (*PFNVIPERVERTEX3DPROC)(GLdouble x, GLdouble y, GLdouble z);
typedef void (*PFNVIPERVERTEX3DVPROC)(const GLdouble* v);
typedef void (*PFNVIPERVERTEX4SPROC)(GLshort x, GLshort y, GLshort z, GLshort w);
typedef void (*PFNVIPERVERTEX4SVPROC)(const GLshort* v);
typedef void (*PFNVIPERVERTEX4IPROC)(GLint x, GLint y, GLint z, GLint w);
typedef void (*PFNVIPERVERTEX4IVPROC)(const GLint* v);
typedef void (*PFNVIPERVERTEX4FPROC)(GLfloat x, GLfloat y, GLfloat z, GLfloat w);
typedef void (*PFNVIPERVERTEX4FVPROC)(const GLfloat* v);
typedef void (*PFNVIPERVERTEX4DPROC)(GLdouble x, GLdouble y, GLdouble z, GLdouble w);
typedef void (*PFNVIPERVERTEX4DVPROC)(const GLdouble* v);
#define VIPER_GL_ACCUM_BUFFER_BIT 0x00000200
#define VIPER_GL_MODELVIEW 0x1700
#define VIPER_GL_PROJECTION 0x1701
#define VIPER_GL_MODELVIEW_MATRIX 0x0BA6
#define VIPER_GL_PROJECTION_MATRIX 0x0BA7
#define VIPER_GL_VERTEX_ARRAY 0x8074
#define VIPER_GL_VERTEX_ARRAY_SIZE 0x807A
#define VIPER_GL_VERTEX_ARRAY_TYPE 0x807B
#define VIPER_GL_VERTEX_ARRAY_STRIDE 0x807C
#define VIPER_GL_VERTEX_ARRAY_POINTER 0x808E
#define VIPER_GL_VERTEX_ARRAY_BUFFER_BINDING 0x8896

namespace viper {
namespace capture {

// Every GL function the interceptor calls for real: (PFN type, name without the gl prefix).
#define VIPER_REAL_GL_FUNCTIONS(X)                                                        \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                  \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                                \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                    \
  X(PFNGLISSHADERPROC, IsShader)                                                          \
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
  X(PFNGLGETTEXTURELEVELPARAMETERIVPROC, GetTextureLevelParameteriv)                      \
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
  X(PFNGLCOLORMASKPROC, ColorMask)                                                        \
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
  X(PFNGLFENCESYNCPROC, FenceSync)                                                        \
  X(PFNGLCLIENTWAITSYNCPROC, ClientWaitSync)                                              \
  X(PFNGLDELETESYNCPROC, DeleteSync)                                                      \
  X(PFNGLGETSTRINGIPROC, GetStringi)                                                      \
  X(PFNGLGETSTRINGPROC, GetString)                                                        \
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
  X(PFNGLCREATESHADERPROC, CreateShader)                                                  \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                                  \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                        \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                                        \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                                        \
  X(PFNGLGETQUERYIVPROC, GetQueryiv)                                                      \
  X(PFNGLPROGRAMPARAMETERIPROC, ProgramParameteri)                                        \
  X(PFNGLGETACTIVEUNIFORMNAMEPROC, GetActiveUniformName)                                  \
  X(PFNGLGETPROGRAMINTERFACEIVPROC, GetProgramInterfaceiv)                                \
  X(PFNGLGETPROGRAMRESOURCEINDEXPROC, GetProgramResourceIndex)                            \
  X(PFNGLGETPROGRAMRESOURCENAMEPROC, GetProgramResourceName)                              \
  X(PFNGLGETPROGRAMRESOURCEIVPROC, GetProgramResourceiv)                                  \
  X(PFNVIPERGETOBJECTPARAMETERIVARBPROC, GetObjectParameterivARB)                         \
  X(PFNGLCOMPRESSEDTEXIMAGE2DPROC, CompressedTexImage2D)                                  \
  X(PFNGLCOMPRESSEDTEXSUBIMAGE2DPROC, CompressedTexSubImage2D)                            \
  X(PFNGLGETFLOATVPROC, GetFloatv)                                                        \
  X(PFNGLGETDOUBLEVPROC, GetDoublev)                                                      \
  X(PFNGLGETINTEGER64VPROC, GetInteger64v)                                                \
  X(PFNGLGETFRAMEBUFFERPARAMETERIVPROC, GetFramebufferParameteriv)                        \
  X(PFNGLGETPOINTERVPROC, GetPointerv)                                                    \
  X(PFNVIPERMATRIXMODEPROC, MatrixMode)                                                   \
  X(PFNVIPERVOIDPROC, LoadIdentity)                                                       \
  X(PFNVIPERMATRIXFPROC, LoadMatrixf)                                                     \
  X(PFNVIPERMATRIXDPROC, LoadMatrixd)                                                     \
  X(PFNVIPERMATRIXFPROC, MultMatrixf)                                                     \
  X(PFNVIPERMATRIXDPROC, MultMatrixd)                                                     \
  X(PFNVIPERVOIDPROC, PushMatrix)                                                         \
  X(PFNVIPERVOIDPROC, PopMatrix)                                                          \
  X(PFNVIPERXYZFPROC, Translatef)                                                         \
  X(PFNVIPERXYZDPROC, Translated)                                                         \
  X(PFNVIPERXYZFPROC, Scalef)                                                             \
  X(PFNVIPERXYZDPROC, Scaled)                                                             \
  X(PFNVIPERROTATEFPROC, Rotatef)                                                         \
  X(PFNVIPERROTATEDPROC, Rotated)                                                         \
  X(PFNVIPERACCUMPROC, Accum)                                                             \
  X(PFNVIPERBEGINPROC, Begin)                                                             \
  X(PFNVIPERCALLLISTPROC, CallList)                                                       \
  X(PFNVIPERCALLLISTSPROC, CallLists)                                                     \
  X(PFNVIPERVOIDPROC, End)                                                                \
  X(PFNVIPERNEWLISTPROC, NewList)                                                         \
  X(PFNVIPERVOIDPROC, EndList)                                                            \
  X(PFNVIPERVERTEX2SPROC, Vertex2s)                                                       \
  X(PFNVIPERVERTEX2SVPROC, Vertex2sv)                                                     \
  X(PFNVIPERVERTEX2IPROC, Vertex2i)                                                       \
  X(PFNVIPERVERTEX2IVPROC, Vertex2iv)                                                     \
  X(PFNVIPERVERTEX2FPROC, Vertex2f)                                                       \
  X(PFNVIPERVERTEX2FVPROC, Vertex2fv)                                                     \
  X(PFNVIPERVERTEX2DPROC, Vertex2d)                                                       \
  X(PFNVIPERVERTEX2DVPROC, Vertex2dv)                                                     \
  X(PFNVIPERVERTEX3SPROC, Vertex3s)                                                       \
  X(PFNVIPERVERTEX3SVPROC, Vertex3sv)                                                     \
  X(PFNVIPERVERTEX3IPROC, Vertex3i)                                                       \
  X(PFNVIPERVERTEX3IVPROC, Vertex3iv)                                                     \
  X(PFNVIPERVERTEX3FPROC, Vertex3f)                                                       \
  X(PFNVIPERVERTEX3FVPROC, Vertex3fv)                                                     \
  X(PFNVIPERVERTEX3DPROC, Vertex3d)                                                       \
  X(PFNVIPERVERTEX3DVPROC, Vertex3dv)                                                     \
  X(PFNVIPERVERTEX4SPROC, Vertex4s)                                                       \
  X(PFNVIPERVERTEX4SVPROC, Vertex4sv)                                                     \
  X(PFNVIPERVERTEX4IPROC, Vertex4i)                                                       \
  X(PFNVIPERVERTEX4IVPROC, Vertex4iv)                                                     \
  X(PFNVIPERVERTEX4FPROC, Vertex4f)                                                       \
  X(PFNVIPERVERTEX4FVPROC, Vertex4fv)                                                     \
  X(PFNVIPERVERTEX4DPROC, Vertex4d)                                                       \
  X(PFNVIPERVERTEX4DVPROC, Vertex4dv)

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

/// Whether the current context's OpenGL version is at least major.minor, from GL_VERSION (which
/// every version answers, unlike GL_MAJOR_VERSION: an error before GL 3.0 that the program would
/// read as its own). False for OpenGL ES.
inline bool glVersionAtLeast(int major, int minor) {
  const GLubyte* v = gl().GetString ? gl().GetString(GL_VERSION) : nullptr;
  if (!v || v[0] < '0' || v[0] > '9') return false;
  int have_major = 0, have_minor = 0;
  const char* p = reinterpret_cast<const char*>(v);
  while (*p >= '0' && *p <= '9') have_major = have_major * 10 + (*p++ - '0');
  if (*p == '.') ++p;
  while (*p >= '0' && *p <= '9') have_minor = have_minor * 10 + (*p++ - '0');
  return have_major > major || (have_major == major && have_minor >= minor);
}

/// Whether the current context has the extension `name` (GL_NUM_EXTENSIONS and glGetStringi from
/// GL 3.0, the GL_EXTENSIONS string before).
bool glHasExtension(const char* name);

/// A parameter of an attachment of the bound draw framebuffer, through the real GL.
inline GLint drawAttachmentParam(GLenum attachment, GLenum pname) {
  GLint v = 0;
  gl().GetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, attachment, pname, &v);
  return v;
}

/// The real dlsym (the interceptor interposes dlsym itself).
void* realDlsym(void* handle, const char* name);
/// glibc's dlsym itself (null if not found), for a jump to it that keeps the caller's return address.
void* realDlsymFunction();

/// A real EGL or GLX function by name, from libEGL.so.1 or libGLX.so.0/libGL.so.1; null if absent.
void* realEglFunction(const char* name);
void* realGlxFunction(const char* name);

}  // namespace capture
}  // namespace viper
