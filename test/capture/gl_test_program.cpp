// Small OpenGL 3.3 core program for the capture tests: renders test_scene_layout.h into an EGL
// pbuffer (or a GLX window), loading GL in one of several ways, and writes its own last frame.
//   gl_test_program [--mode direct|eglproc|dlopen|glx] [--size WxH] [--frames N] [--out FILE]
//                   [--load N] [--offscreen 0|1] [--frame-ms T]
// --out writes the program's own glReadPixels of its last frame (RGBA, bottom row first).
// --load adds N small extra quads per frame (for overhead measurements). Prints frame_ms=AVG.
// --frame-ms T paces frames to at least T ms each (sleeping after glFinish), as a game held to
// its display's rate is: the overhead of a capture on a program with a frame budget.
// --offscreen 1 renders the scene into a framebuffer object of its own (color texture, depth
// renderbuffer) and composites it into the default framebuffer with a post effect (inverted
// colors), as engines with post-processing do. --offscreen 2 does the same with a depth texture
// instead of the renderbuffer, after a shadow-map-like pass (the quad into a 64x64 depth-only
// framebuffer object) that a capture must leave out.
#include "test_scene_layout.h"  // Eigen before X11 (X11 defines Success)
#include "fullscreen_triangle.h"
#include "gl_common/sanitizer_options.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <dlfcn.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace {

#define GL_FUNCS(X)                                                                                         \
  X(PFNGLCREATESHADERPROC, CreateShader) X(PFNGLSHADERSOURCEPROC, ShaderSource)                            \
  X(PFNGLCOMPILESHADERPROC, CompileShader) X(PFNGLGETSHADERIVPROC, GetShaderiv)                            \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog) X(PFNGLCREATEPROGRAMPROC, CreateProgram)                  \
  X(PFNGLATTACHSHADERPROC, AttachShader) X(PFNGLLINKPROGRAMPROC, LinkProgram)                              \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv) X(PFNGLUSEPROGRAMPROC, UseProgram)                                \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation) X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)        \
  X(PFNGLUNIFORM4FPROC, Uniform4f) X(PFNGLGETATTRIBLOCATIONPROC, GetAttribLocation)                         \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays) X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                \
  X(PFNGLGENBUFFERSPROC, GenBuffers) X(PFNGLBINDBUFFERPROC, BindBuffer) X(PFNGLBUFFERDATAPROC, BufferData) \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                                      \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) X(PFNGLVIEWPORTPROC, Viewport)              \
  X(PFNGLCLEARCOLORPROC, ClearColor) X(PFNGLCLEARPROC, Clear) X(PFNGLENABLEPROC, Enable)                   \
  X(PFNGLDISABLEPROC, Disable) X(PFNGLBLENDFUNCPROC, BlendFunc) X(PFNGLDEPTHMASKPROC, DepthMask)           \
  X(PFNGLDRAWARRAYSPROC, DrawArrays) X(PFNGLDRAWELEMENTSPROC, DrawElements)                                 \
  X(PFNGLDRAWELEMENTSBASEVERTEXPROC, DrawElementsBaseVertex) X(PFNGLREADPIXELSPROC, ReadPixels)            \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer) X(PFNGLDRAWBUFFERPROC, DrawBuffer)                          \
  X(PFNGLPIXELSTOREIPROC, PixelStorei) X(PFNGLFINISHPROC, Finish) X(PFNGLGETERRORPROC, GetError)           \
  X(PFNGLGETINTEGERVPROC, GetIntegerv) X(PFNGLGENTEXTURESPROC, GenTextures)                                 \
  X(PFNGLBINDTEXTUREPROC, BindTexture) X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                   \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri) X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                         \
  X(PFNGLUNIFORM1IPROC, Uniform1i) X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                         \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D) X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)    \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer) X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)      \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                              \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus) X(PFNGLGETSTRINGPROC, GetString)

struct Gl {
#define DECL(type, name) type name = nullptr;
  GL_FUNCS(DECL)
#undef DECL
};

using GetProc = void* (*)(const char*);

void loadGl(Gl& g, GetProc proc) {
#define LOAD(type, name) g.name = reinterpret_cast<type>(proc ? proc("gl" #name) : nullptr);
  GL_FUNCS(LOAD)
#undef LOAD
}

void linkGl(Gl& g) {
#define LINK(type, name) g.name = &::gl##name;
  GL_FUNCS(LINK)
#undef LINK
}

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "gl_test_program: %s\n", what.c_str());
  std::exit(1);
}

GLuint compile(const Gl& g, GLenum type, const char* src) {
  GLuint s = g.CreateShader(type);
  g.ShaderSource(s, 1, &src, nullptr);
  g.CompileShader(s);
  GLint ok = 0;
  g.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    g.GetShaderInfoLog(s, sizeof(log), nullptr, log);
    die(std::string("shader: ") + log);
  }
  return s;
}

GLuint program(const Gl& g, const char* vs, const char* fs) {
  GLuint p = g.CreateProgram();
  g.AttachShader(p, compile(g, GL_VERTEX_SHADER, vs));
  g.AttachShader(p, compile(g, GL_FRAGMENT_SHADER, fs));
  g.LinkProgram(p);
  GLint ok = 0;
  g.GetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) die("link failed");
  return p;
}

const char* kRigidVs = R"(#version 330 core
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
in vec3 aPos;
void main() { gl_Position = uProj * uView * uWorld * vec4(aPos, 1.0); }
)";
const char* kColorFs = R"(#version 330 core
// a comment that mentions void main() on purpose
uniform vec4 uColor;
layout(location = 0) out vec4 fragColor;
void main ( void ) { fragColor = uColor; }
)";
const char* kGlassFs = R"(#version 330 core
uniform vec4 uColor;
uniform sampler2D uTint;
out vec4 color;
void main() { color = uColor * texture(uTint, vec2(0.5)); }
)";
const char* kSkinVs = R"(#version 330 core
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
uniform mat4 uBones[2];
in vec3 aPos;
in float aWeight;
void main() {
  vec4 p = vec4(aPos, 1.0);
  vec4 skinned = (1.0 - aWeight) * (uBones[0] * p) + aWeight * (uBones[1] * p);
  gl_Position = uProj * uView * uWorld * skinned;
}
)";

// The composite pass (fullscreen_triangle.h's triangle over the whole screen) shows the scene's
// colors inverted.
const char* kPostFs = R"(#version 330 core
uniform sampler2D uScene;
in vec2 uv;
out vec4 color;
void main() { color = vec4(1.0 - texture(uScene, uv).rgb, 1.0); }
)";

// A width x height depth texture on unit 3 (unit 0 keeps its binding).
GLuint depthTexture(const Gl& g, int width, int height) {
  GLuint t = 0;
  g.GenTextures(1, &t);
  g.ActiveTexture(GL_TEXTURE3);
  g.BindTexture(GL_TEXTURE_2D, t);
  g.TexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, width, height, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
  g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  g.ActiveTexture(GL_TEXTURE0);
  return t;
}

struct Mesh {
  GLuint vao = 0;
};

template <typename T>
GLuint buffer(const Gl& g, GLenum target, const std::vector<T>& data) {
  GLuint b = 0;
  g.GenBuffers(1, &b);
  g.BindBuffer(target, b);
  g.BufferData(target, static_cast<GLsizeiptr>(data.size() * sizeof(T)), data.data(), GL_STATIC_DRAW);
  return b;
}

void setMatrices(const Gl& g, GLuint prog, const Eigen::Matrix4f& world) {
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "uWorld"), 1, GL_FALSE, world.data());
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "uView"), 1, GL_FALSE, viper::test_scene::view().data());
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "uProj"), 1, GL_FALSE, viper::test_scene::projection().data());
}

}  // namespace

int main(int argc, char** argv) {
  namespace ts = viper::test_scene;
  std::string mode = "direct", out;
  int width = 160, height = 120, frames = 3, load = 0, offscreen = 0;
  double frame_budget_ms = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--mode") mode = v;
    else if (a == "--size") std::sscanf(v.c_str(), "%dx%d", &width, &height);
    else if (a == "--frames") frames = std::atoi(v.c_str());
    else if (a == "--out") out = v;
    else if (a == "--load") load = std::atoi(v.c_str());
    else if (a == "--frame-ms") frame_budget_ms = std::atof(v.c_str());
    else if (a == "--offscreen") offscreen = std::atoi(v.c_str());
    else die("unknown option " + a);
  }

  Gl g;
  // Window system: EGL pbuffer (linked or dlopen'ed) or GLX window.
  using SwapFn = void (*)();
  SwapFn swap = nullptr;
  static EGLDisplay dpy;
  static EGLSurface surface;
  static EGLBoolean (*egl_swap)(EGLDisplay, EGLSurface) = nullptr;
  static Display* xdpy;
  static unsigned long xwin;
  static void (*glx_swap)(Display*, unsigned long) = nullptr;
  if (mode == "glx") {
    xdpy = XOpenDisplay(nullptr);
    if (!xdpy) die("no X display (run under xvfb-run)");
    void* libgl = dlopen("libGL.so.1", RTLD_NOW);
    if (!libgl) die("no libGL.so.1");
    auto getproc = reinterpret_cast<void* (*)(const unsigned char*)>(dlsym(libgl, "glXGetProcAddressARB"));
    using ChooseFn = void** (*)(Display*, int, const int*, int*);
    auto choose = reinterpret_cast<ChooseFn>(getproc((const unsigned char*)"glXChooseFBConfig"));
    const int fb_attrs[] = {0x8010 /*DRAWABLE_TYPE*/, 1 /*WINDOW_BIT*/, 5 /*DOUBLEBUFFER*/, 1, 8, 8, 9, 8, 10, 8,
                            12 /*DEPTH_SIZE*/, 24, 0};
    int n = 0;
    void** configs = choose(xdpy, DefaultScreen(xdpy), fb_attrs, &n);
    if (!configs || n == 0) die("no GLX config");
    using VisualFn = XVisualInfo* (*)(Display*, void*);
    XVisualInfo* vi = reinterpret_cast<VisualFn>(getproc((const unsigned char*)"glXGetVisualFromFBConfig"))(xdpy, configs[0]);
    XSetWindowAttributes swa{};
    swa.colormap = XCreateColormap(xdpy, RootWindow(xdpy, vi->screen), vi->visual, AllocNone);
    xwin = XCreateWindow(xdpy, RootWindow(xdpy, vi->screen), 0, 0, width, height, 0, vi->depth, InputOutput,
                         vi->visual, CWColormap, &swa);
    XMapWindow(xdpy, xwin);
    XSync(xdpy, False);
    using CreateFn = void* (*)(Display*, void*, void*, int, const int*);
    auto create = reinterpret_cast<CreateFn>(getproc((const unsigned char*)"glXCreateContextAttribsARB"));
    const int ctx_attrs[] = {0x2091, 3, 0x2092, 3, 0x9126, 1 /*core*/, 0};
    void* ctx = create(xdpy, configs[0], nullptr, 1, ctx_attrs);
    if (!ctx) die("no GLX context");
    using MakeFn = int (*)(Display*, unsigned long, void*);
    reinterpret_cast<MakeFn>(getproc((const unsigned char*)"glXMakeCurrent"))(xdpy, xwin, ctx);
    glx_swap = reinterpret_cast<void (*)(Display*, unsigned long)>(getproc((const unsigned char*)"glXSwapBuffers"));
    swap = [] { glx_swap(xdpy, xwin); };
    loadGl(g, reinterpret_cast<GetProc>(getproc));
  } else {
    // EGL entry points: linked, or (mode dlopen) looked up with dlsym like many engines do.
    using GetDisplayFn = EGLDisplay (*)(EGLenum, void*, const EGLAttrib*);
    GetDisplayFn get_display = &eglGetPlatformDisplay;
    auto initialize = &eglInitialize;
    auto choose = &eglChooseConfig;
    auto bind_api = &eglBindAPI;
    auto create_surface = &eglCreatePbufferSurface;
    auto create_context = &eglCreateContext;
    auto make_current = &eglMakeCurrent;
    egl_swap = &eglSwapBuffers;
    GetProc getproc = reinterpret_cast<GetProc>(&eglGetProcAddress);
    if (mode == "dlopen") {
      void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
      if (!lib) die("no libEGL.so.1");
      get_display = reinterpret_cast<GetDisplayFn>(dlsym(lib, "eglGetPlatformDisplay"));
      initialize = reinterpret_cast<decltype(initialize)>(dlsym(lib, "eglInitialize"));
      choose = reinterpret_cast<decltype(choose)>(dlsym(lib, "eglChooseConfig"));
      bind_api = reinterpret_cast<decltype(bind_api)>(dlsym(lib, "eglBindAPI"));
      create_surface = reinterpret_cast<decltype(create_surface)>(dlsym(lib, "eglCreatePbufferSurface"));
      create_context = reinterpret_cast<decltype(create_context)>(dlsym(lib, "eglCreateContext"));
      make_current = reinterpret_cast<decltype(make_current)>(dlsym(lib, "eglMakeCurrent"));
      egl_swap = reinterpret_cast<decltype(egl_swap)>(dlsym(lib, "eglSwapBuffers"));
      getproc = reinterpret_cast<GetProc>(dlsym(lib, "eglGetProcAddress"));
    }
    dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (dpy == EGL_NO_DISPLAY || !initialize(dpy, nullptr, nullptr)) {
      // A GPU driver without Mesa's platforms (NVIDIA's EGL without an X server): its first device.
      const auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(getproc("eglQueryDevicesEXT"));
      EGLDeviceEXT device = nullptr;
      EGLint count = 0;
      if (query_devices && query_devices(1, &device, &count) && count > 0)
        dpy = get_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
      if (dpy == EGL_NO_DISPLAY || !initialize(dpy, nullptr, nullptr)) die("no EGL display");
    }
    const EGLint cfg_attrs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
                                EGL_DEPTH_SIZE, 24, EGL_NONE};
    EGLConfig cfg;
    EGLint n = 0;
    if (!choose(dpy, cfg_attrs, &cfg, 1, &n) || n == 0) die("no EGL config");
    bind_api(EGL_OPENGL_API);
    const EGLint surf_attrs[] = {EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE};
    surface = create_surface(dpy, cfg, surf_attrs);
    const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = create_context(dpy, cfg, EGL_NO_CONTEXT, ctx_attrs);
    if (surface == EGL_NO_SURFACE || ctx == EGL_NO_CONTEXT) die("no EGL surface/context");
    if (!make_current(dpy, surface, surface, ctx)) die("eglMakeCurrent failed");
    swap = [] { egl_swap(dpy, surface); };
    if (mode == "direct") linkGl(g);
    else loadGl(g, getproc);
  }
  if (!g.DrawElementsBaseVertex) die("GL functions missing");
  if (g.GetString) std::printf("renderer=%s\n", reinterpret_cast<const char*>(g.GetString(GL_RENDERER)));

  const GLuint rigid = program(g, kRigidVs, kColorFs);
  const GLuint glass = program(g, kRigidVs, kGlassFs);
  const GLuint skin = program(g, kSkinVs, kColorFs);

  auto vao = [&]() {
    GLuint v = 0;
    g.GenVertexArrays(1, &v);
    g.BindVertexArray(v);
    return v;
  };
  auto positions = [&](GLuint prog, GLsizei stride) {
    const GLuint loc = static_cast<GLuint>(g.GetAttribLocation(prog, "aPos"));
    g.VertexAttribPointer(loc, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    g.EnableVertexAttribArray(loc);
  };
  const GLuint quad_vao = vao();
  buffer(g, GL_ARRAY_BUFFER, ts::quadVertices());
  buffer(g, GL_ELEMENT_ARRAY_BUFFER, ts::quadIndices());
  positions(rigid, 0);
  const GLuint tri_vao = vao();
  buffer(g, GL_ARRAY_BUFFER, ts::triangleVertices());
  positions(rigid, 0);
  const GLuint glass_vao = vao();
  buffer(g, GL_ARRAY_BUFFER, ts::glassVertices());
  positions(glass, 0);
  const GLuint skin_vao = vao();
  buffer(g, GL_ARRAY_BUFFER, ts::skinnedVertices());
  buffer(g, GL_ELEMENT_ARRAY_BUFFER, ts::skinnedIndices());
  positions(skin, 16);
  const GLuint weight = static_cast<GLuint>(g.GetAttribLocation(skin, "aWeight"));
  g.VertexAttribPointer(weight, 1, GL_FLOAT, GL_FALSE, 16, reinterpret_cast<void*>(12));
  g.EnableVertexAttribArray(weight);

  // A 2x2 white tint texture for the glass, on texture unit 1.
  GLuint tint = 0;
  g.GenTextures(1, &tint);
  g.ActiveTexture(GL_TEXTURE1);
  g.BindTexture(GL_TEXTURE_2D, tint);
  const uint8_t white[16] = {255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255};
  g.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 2, 2, 0, GL_RGBA, GL_UNSIGNED_BYTE, white);
  g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  g.ActiveTexture(GL_TEXTURE0);
  g.UseProgram(glass);
  g.Uniform1i(g.GetUniformLocation(glass, "uTint"), 1);

  // The scene's framebuffer object (--offscreen): color texture on unit 2, depth renderbuffer.
  GLuint scene_fb = 0, scene_color = 0, scene_depth = 0, post = 0, post_vao = 0;
  if (offscreen) {
    g.GenTextures(1, &scene_color);
    g.ActiveTexture(GL_TEXTURE2);
    g.BindTexture(GL_TEXTURE_2D, scene_color);
    g.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    g.ActiveTexture(GL_TEXTURE0);
    g.GenFramebuffers(1, &scene_fb);
    g.BindFramebuffer(GL_FRAMEBUFFER, scene_fb);
    g.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, scene_color, 0);
    if (offscreen == 1) {
      g.GenRenderbuffers(1, &scene_depth);
      g.BindRenderbuffer(GL_RENDERBUFFER, scene_depth);
      g.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
      g.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, scene_depth);
    } else {
      scene_depth = depthTexture(g, width, height);
      g.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, scene_depth, 0);
    }
    if (g.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("scene framebuffer incomplete");
    post = program(g, viper::test_program::kFullScreenTriangleVs, kPostFs);
    g.UseProgram(post);
    g.Uniform1i(g.GetUniformLocation(post, "uScene"), 2);
    post_vao = vao();
  }
  GLuint shadow_fb = 0;
  if (offscreen == 2) {
    g.GenFramebuffers(1, &shadow_fb);
    g.BindFramebuffer(GL_FRAMEBUFFER, shadow_fb);
    g.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depthTexture(g, 64, 64), 0);
    g.DrawBuffer(GL_NONE);
    if (g.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("shadow framebuffer incomplete");
  }

  std::vector<uint8_t> pixels(static_cast<size_t>(width) * height * 4);
  double total_ms = 0;
  for (int f = 0; f < frames; ++f) {
    const auto start = std::chrono::steady_clock::now();
    if (shadow_fb) {
      g.BindFramebuffer(GL_FRAMEBUFFER, shadow_fb);
      g.Viewport(0, 0, 64, 64);
      g.Enable(GL_DEPTH_TEST);
      g.Clear(GL_DEPTH_BUFFER_BIT);
      g.UseProgram(rigid);
      setMatrices(g, rigid, ts::world(ts::kQuad, f));
      g.BindVertexArray(quad_vao);
      g.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr);
    }
    g.BindFramebuffer(GL_FRAMEBUFFER, scene_fb);
    GLint bound = -1;
    g.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    if (bound != static_cast<GLint>(scene_fb)) die("the bound framebuffer does not read back as bound");
    g.DrawBuffer(offscreen ? GL_COLOR_ATTACHMENT0 : GL_BACK);
    g.Viewport(0, 0, width, height);
    g.ClearColor(0.1f, 0.1f, 0.2f, 1.0f);
    g.Enable(GL_DEPTH_TEST);
    g.DepthMask(GL_TRUE);
    g.Disable(GL_BLEND);
    g.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    g.UseProgram(rigid);
    setMatrices(g, rigid, ts::world(ts::kQuad, f));
    g.Uniform4f(g.GetUniformLocation(rigid, "uColor"), 0.9f, 0.1f, 0.1f, 1.0f);
    g.BindVertexArray(quad_vao);
    g.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr);
    setMatrices(g, rigid, ts::world(ts::kTriangle, f));
    g.Uniform4f(g.GetUniformLocation(rigid, "uColor"), 0.1f, 0.8f, 0.1f, 1.0f);
    g.BindVertexArray(tri_vao);
    g.DrawArrays(GL_TRIANGLES, 0, 3);

    g.UseProgram(glass);
    setMatrices(g, glass, ts::world(ts::kGlass, f));
    g.Uniform4f(g.GetUniformLocation(glass, "uColor"), 0.8f, 0.8f, 1.0f, 0.4f);
    g.Enable(GL_BLEND);
    g.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    g.DepthMask(GL_FALSE);
    g.BindVertexArray(glass_vao);
    g.DrawArrays(GL_TRIANGLES, 0, 6);
    g.DepthMask(GL_TRUE);
    g.Disable(GL_BLEND);

    g.UseProgram(skin);
    setMatrices(g, skin, ts::world(ts::kSkinned, f));
    g.Uniform4f(g.GetUniformLocation(skin, "uColor"), 0.2f, 0.3f, 0.9f, 1.0f);
    const Eigen::Matrix4f bones[2] = {ts::bone(0, f), ts::bone(1, f)};
    g.UniformMatrix4fv(g.GetUniformLocation(skin, "uBones[0]"), 1, GL_FALSE, bones[0].data());
    g.UniformMatrix4fv(g.GetUniformLocation(skin, "uBones[1]"), 1, GL_FALSE, bones[1].data());
    g.BindVertexArray(skin_vao);
    g.DrawElementsBaseVertex(GL_TRIANGLES, 24, GL_UNSIGNED_INT, nullptr, ts::kSkinPadding);

    // Extra load: small quads in a grid over the lower band (draws 4...).
    g.UseProgram(rigid);
    g.BindVertexArray(quad_vao);
    for (int i = 0; i < load; ++i) {
      Eigen::Matrix4f w = ts::translation(-1.9f + 0.1f * (i % 38), -1.4f + 0.05f * ((i / 38) % 8), 0.2f);
      w(0, 0) = w(1, 1) = 0.04f;
      setMatrices(g, rigid, w);
      g.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr);
    }

    if (offscreen) {
      g.BindFramebuffer(GL_FRAMEBUFFER, 0);
      g.DrawBuffer(GL_BACK);
      g.Disable(GL_DEPTH_TEST);
      g.UseProgram(post);
      g.BindVertexArray(post_vao);
      g.DrawArrays(GL_TRIANGLES, 0, 3);
    }

    if (f == frames - 1 && !out.empty()) {
      g.PixelStorei(GL_PACK_ALIGNMENT, 1);
      g.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    }
    swap();
    g.Finish();
    if (frame_budget_ms > 0)
      std::this_thread::sleep_until(start + std::chrono::duration<double, std::milli>(frame_budget_ms));
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (f > 0) total_ms += ms;
  }
  if (g.GetError() != GL_NO_ERROR) die("GL error");
  if (!out.empty()) {
    std::ofstream file(out, std::ios::binary);
    file.write(reinterpret_cast<const char*>(pixels.data()), static_cast<std::streamsize>(pixels.size()));
  }
  std::printf("frame_ms=%.3f\n", frames > 1 ? total_ms / (frames - 1) : 0.0);
  return 0;
}
