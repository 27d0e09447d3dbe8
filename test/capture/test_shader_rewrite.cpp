// GLSL rewriting for draw/primitive ids: string-level checks, then compile and link of the
// rewritten shaders on a real (headless EGL) context.
#include "viper/capture/shader_rewrite.h"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

using viper::declaresMat4ArrayUniform;
using viper::rewriteFragmentShader;
using viper::stripGlslComments;

namespace {

const char* kLayoutShader = R"(#version 330 core
// void main() in a comment must not be touched
/* nor main() here */
uniform vec4 uColor;
layout(location = 0) out vec4 fragColor;
void main ( void )
{
  fragColor = uColor;
}
)";

const char* kPlainShader = R"(#version 150
in vec2 vUv;
uniform sampler2D uTex;
out vec4 color;
void helper(out vec4 c) { c = texture(uTex, vUv); }
void main() { helper(color); if (color.a < 0.01) discard; }
)";

const char* kMrtShader = R"(#version 330 core
layout(location = 0) out vec4 albedo;
layout(location = 2) out vec4 normal;
void main() { albedo = vec4(1.0); normal = vec4(0.0, 0.0, 1.0, 1.0); }
)";

// The shape of SuperTuxKart 1.4's sp_solid.frag: a G-buffer output at location 1, written only
// when its advanced pipeline is on.
const char* kNormalAtOneShader = R"(#version 330
in vec4 color;
layout(location = 0) out vec4 o_diffuse_color;
layout(location = 1) out vec4 o_normal_color;
void main(void) { o_diffuse_color = vec4(color.xyz, 1.0); }
)";

int countOf(const std::string& s, const std::string& what) {
  int n = 0;
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST(ShaderRewrite, StripsCommentsKeepingLines) {
  const std::string in = "a // main()\nb /* x\ny */ c\n";
  const std::string out = stripGlslComments(in);
  EXPECT_EQ(out.size(), in.size());
  EXPECT_EQ(countOf(out, "\n"), 3);
  EXPECT_EQ(out.find("main"), std::string::npos);
  EXPECT_NE(out.find('c'), std::string::npos);
}

TEST(ShaderRewrite, LayoutOutputAndSpacedMain) {
  const auto r = rewriteFragmentShader(kLayoutShader);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.color_output, "fragColor");
  EXPECT_TRUE(r.explicit_location);
  EXPECT_EQ(countOf(r.source, "void viper_original_main()"), 1);
  EXPECT_EQ(countOf(r.source, "void main()"), 1);
  EXPECT_EQ(countOf(r.source, "viper_id_out = (viper_alpha_test > 0.5 && fragColor.a < 0.5) ? vec4(0.0, 0.0, 0.0, "
                              "1.0) : vec4(viper_draw_id, float(gl_PrimitiveID), 0.0, 1.0);"),
            1);
}

TEST(ShaderRewrite, PlainOutputWithOutParameterHelper) {
  const auto r = rewriteFragmentShader(kPlainShader);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.color_output, "color");  // `out vec4 c` of the helper is a parameter, not an output
  EXPECT_FALSE(r.explicit_location);
}

TEST(ShaderRewrite, MrtUsesLocationZero) {
  const auto r = rewriteFragmentShader(kMrtShader);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.color_output, "albedo");
}

TEST(ShaderRewrite, ProgramOutputAtLocationOneKeepsIt) {
  const auto r = rewriteFragmentShader(kNormalAtOneShader);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.color_output, "o_diffuse_color");
  EXPECT_EQ(countOf(r.source, "layout(location = 1) out vec4 o_normal_color;"), 1);
}

TEST(ShaderRewrite, RefusesWhatItCannotHandle) {
  EXPECT_FALSE(rewriteFragmentShader("#version 120\nvoid main() { float x = 1.0; }\n").ok);  // writes no color
  EXPECT_FALSE(rewriteFragmentShader("#version 130\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n").ok);
  EXPECT_FALSE(rewriteFragmentShader("#version 300 es\nout highp vec4 c;\nvoid main() { c = vec4(1.0); }\n").ok);
  EXPECT_FALSE(rewriteFragmentShader("#version 330\nout vec4 a;\nout vec4 b;\nvoid main() {}\n").ok);
  const auto at_ours =
      rewriteFragmentShader("#version 330\nlayout(location=0) out vec4 a;\nlayout(location=7) out vec4 b;\n"
                            "void main() {}\n");
  EXPECT_FALSE(at_ours.ok);
  EXPECT_NE(at_ours.reason.find("'b' at location 7"), std::string::npos) << at_ours.reason;
  const auto dual = rewriteFragmentShader(
      "#version 330\nlayout(location=0, index=0) out vec4 a;\nlayout(location=0, index=1) out vec4 b;\n"
      "void main() {}\n");
  EXPECT_FALSE(dual.ok);
  EXPECT_NE(dual.reason.find("dual-source"), std::string::npos) << dual.reason;
  EXPECT_FALSE(rewriteFragmentShader("#version 330\nvoid main() {}\n").ok);
}

// Minetest's shape: GLSL 1.20 from a compatibility context (blank lines before #version), gl_FragColor.
const char* kLegacyShader = "\n\n#version 120\n#define ENABLE_TONE_MAPPING 1\nuniform sampler2D baseTexture;\n"
                            "varying vec2 uv;\nvoid main(void)\n{\n  vec4 col = texture2D(baseTexture, uv);\n"
                            "  gl_FragColor = col;\n}\n";

TEST(ShaderRewrite, LegacyGlslWritesItsColorAndTheIdsThroughFragData) {
  const auto r = rewriteFragmentShader(kLegacyShader);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.legacy);
  EXPECT_EQ(r.source.find("gl_FragColor"), std::string::npos);
  // gl_FragColor goes to every draw buffer: the colour to the first seven, and to the last one
  // (where the ids go) while viper_draw_id is 0 (no ids wanted).
  EXPECT_EQ(countOf(r.source, "viper_frag_color = col;"), 1);
  EXPECT_EQ(countOf(r.source, "vec4 viper_frag_color;"), 1);
  for (int i = 0; i < 7; ++i)
    EXPECT_EQ(countOf(r.source, "gl_FragData[" + std::to_string(i) + "] = viper_frag_color;"), 1) << i;
  // The id where the fragment is mostly opaque, id 0 where a blended one is mostly transparent.
  EXPECT_EQ(countOf(r.source, "gl_FragData[7] = viper_draw_id < 0.5 ? viper_frag_color : ((viper_alpha_test > 0.5 && "
                              "viper_frag_color.a < 0.5) ? vec4(0.0, 0.0, 0.0, 1.0) : "
                              "vec4(viper_draw_id, float(gl_PrimitiveID), 0.0, 1.0));"),
            1);
  // A shader that writes gl_FragData itself keeps its draw buffers; the ids go to the last, while
  // they are wanted (else the program's own gl_FragData[7], written by a loop, stays).
  const auto data = rewriteFragmentShader("#version 120\nvoid main() { gl_FragData[0] = vec4(1.0); }\n");
  ASSERT_TRUE(data.ok) << data.reason;
  EXPECT_EQ(countOf(data.source, "gl_FragData[0] = vec4(1.0);"), 1);
  EXPECT_EQ(countOf(data.source, "if (viper_draw_id >= 0.5) gl_FragData[7] = (viper_alpha_test > 0.5 && gl_FragData[0].a < 0.5) ? "
                                 "vec4(0.0, 0.0, 0.0, 1.0) : vec4(viper_draw_id, float(gl_PrimitiveID), 0.0, 1.0);"),
            1);
  // One that writes the last draw buffer itself is left alone.
  EXPECT_FALSE(rewriteFragmentShader("#version 120\nvoid main() { gl_FragData[ 7 ] = vec4(1.0); }\n").ok);
  // The colour variable is declared after the last of several #extension directives (which must
  // come before any declaration: piglit's tex-miplevel-selection has three).
  const auto extensions = rewriteFragmentShader(
      "#version 120\n#extension GL_ARB_a : enable\n#extension GL_ARB_b : enable\n  #extension GL_ARB_c : enable\n"
      "uniform float u;\nvoid main() { gl_FragColor = vec4(u); }\n");
  ASSERT_TRUE(extensions.ok) << extensions.reason;
  EXPECT_LT(extensions.source.find("#extension GL_ARB_c"), extensions.source.find("vec4 viper_frag_color;"));
  EXPECT_LT(extensions.source.find("vec4 viper_frag_color;"), extensions.source.find("uniform float u;"));
  // Without primitive ids (a geometry stage that writes none): 0, and no extension needed.
  const auto without = rewriteFragmentShader(kLegacyShader, /*primitive_ids=*/false);
  ASSERT_TRUE(without.ok) << without.reason;
  EXPECT_EQ(without.source.find("gl_PrimitiveID"), std::string::npos);
  EXPECT_EQ(without.source.find("#extension"), std::string::npos);
  EXPECT_EQ(countOf(without.source, "vec4(viper_draw_id, 0.0, 0.0, 1.0)"), 1);
  // The extension directive right after #version, which stays the first directive.
  EXPECT_LT(r.source.find("#version 120"), r.source.find("#extension GL_EXT_gpu_shader4 : require"));
  EXPECT_LT(r.source.find("#extension"), r.source.find("#define"));
  const auto no_version = rewriteFragmentShader("void main() { gl_FragData[0] = vec4(1.0); }\n");
  ASSERT_TRUE(no_version.ok) << no_version.reason;
  EXPECT_EQ(no_version.source.rfind("#extension GL_EXT_gpu_shader4 : require\n", 0), 0u);
}

TEST(ShaderRewrite, Vec3OutputAlwaysWritesItsId) {
  const auto r = rewriteFragmentShader("#version 330\nout vec3 c;\nvoid main() { c = vec3(1.0); }\n");
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.color_components, 3);
  EXPECT_EQ(r.source.find("c.a"), std::string::npos);
  EXPECT_EQ(countOf(r.source, "viper_id_out = vec4(viper_draw_id, float(gl_PrimitiveID), 0.0, 1.0);"), 1);
}

TEST(ShaderRewrite, DetectsBoneArrays) {
  EXPECT_TRUE(declaresMat4ArrayUniform("#version 330\nuniform mat4 uBones[64];\nvoid main(){}\n"));
  EXPECT_TRUE(declaresMat4ArrayUniform("uniform highp mat4 bones [ 4 ];"));
  EXPECT_FALSE(declaresMat4ArrayUniform("uniform mat4 uWorld;\n// uniform mat4 uBones[4];\n"));
}

namespace {

// A surfaceless context of GL `major`.`minor` with `profile_bit` made current (EGL_NO_CONTEXT if none).
EGLContext makeContext(EGLDisplay& dpy, int major, int minor, EGLint profile_bit) {
  dpy = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, nullptr, nullptr)) return EGL_NO_CONTEXT;
  eglBindAPI(EGL_OPENGL_API);
  const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, major, EGL_CONTEXT_MINOR_VERSION, minor,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, profile_bit, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, ctx_attrs);
  if (ctx != EGL_NO_CONTEXT && !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) return EGL_NO_CONTEXT;
  return ctx;
}

// Compiles both shaders and attaches them to `program` (compile logs in the failure message).
void compileAndAttach(GLuint program, const std::string& vs, const std::string& fs) {
  for (auto [type, src] : {std::make_pair(GLenum(GL_VERTEX_SHADER), vs), std::make_pair(GLenum(GL_FRAGMENT_SHADER), fs)}) {
    GLuint s = glCreateShader(type);
    const char* text = src.c_str();
    glShaderSource(s, 1, &text, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    char log[1024] = "";
    glGetShaderInfoLog(s, sizeof(log), nullptr, log);
    ASSERT_TRUE(ok) << log << "\n" << src;
    glAttachShader(program, s);
  }
}

}  // namespace

// Compiles and links the rewritten shaders on a real context; skipped where no EGL is available.
TEST(ShaderRewrite, RewrittenShadersCompileAndLink) {
  EGLDisplay dpy;
  EGLContext ctx = makeContext(dpy, 3, 3, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT);
  if (ctx == EGL_NO_CONTEXT) GTEST_SKIP() << "no surfaceless GL 3.3 context";

  const char* vs = "#version 150\nin vec4 p;\nout vec2 vUv;\nvoid main() { vUv = p.xy; gl_Position = p; }\n";
  for (const char* fs : {kLayoutShader, kPlainShader, kMrtShader, kNormalAtOneShader}) {
    const auto r = rewriteFragmentShader(fs);
    ASSERT_TRUE(r.ok) << r.reason;
    GLuint program = glCreateProgram();
    compileAndAttach(program, vs, r.source);
    if (HasFatalFailure()) return;
    glBindFragDataLocation(program, viper::kIdOutputLocation, viper::kIdOutputName);
    if (!r.explicit_location) glBindFragDataLocation(program, 0, r.color_output.c_str());
    glLinkProgram(program);
    GLint linked = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &linked);
    ASSERT_TRUE(linked);
    EXPECT_EQ(glGetFragDataLocation(program, viper::kIdOutputName), viper::kIdOutputLocation);
    EXPECT_EQ(glGetFragDataLocation(program, r.color_output.c_str()), 0);
    EXPECT_GE(glGetUniformLocation(program, viper::kDrawIdUniform), 0);
    glDeleteProgram(program);
  }
  eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(dpy, ctx);
}

// The legacy rewrite compiles and links in a compatibility context (as Minetest's run).
TEST(ShaderRewrite, LegacyRewriteCompilesInACompatibilityContext) {
  EGLDisplay dpy;
  EGLContext ctx = makeContext(dpy, 3, 0, EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT);
  ASSERT_NE(ctx, EGL_NO_CONTEXT) << "no surfaceless GL 3.0 compatibility context";
  const auto r = rewriteFragmentShader(kLegacyShader);
  ASSERT_TRUE(r.ok) << r.reason;
  const char* vs = "#version 120\nvarying vec2 uv;\nvoid main() { uv = gl_Vertex.xy; gl_Position = gl_Vertex; }\n";
  GLuint program = glCreateProgram();
  compileAndAttach(program, vs, r.source);
  if (HasFatalFailure()) return;
  glLinkProgram(program);
  GLint linked = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  EXPECT_TRUE(linked);
  EXPECT_GE(glGetUniformLocation(program, viper::kDrawIdUniform), 0);
  glDeleteProgram(program);
  eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(dpy, ctx);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
