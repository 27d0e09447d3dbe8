// Draws made without a program (OpenGL 1.x fixed function) in a compatibility context: recorded
// from the fixed-function state (the conventional vertex array, the matrix stack, the texture of
// unit 0), their ids written by an id pass. The id pass draws the same call a second time with
// the layer's id program (ftransform(), which the GLSL specification makes compute the position
// exactly as the fixed-function pipeline does), the program's colour buffers masked, depth tested
// at equal depth with depth writes off: it writes the draw's id where the draw's own fragments
// are now the depth image's, and nothing the program can see changes.
#include "interceptor.h"

#include "viper/capture/shader_rewrite.h"

#include <string>

namespace viper {
namespace capture {

namespace {

constexpr GLenum kAlphaTest = 0x0BC0;
constexpr GLenum kVertexProgramArb = 0x8620;
constexpr GLenum kTexture2d = GL_TEXTURE_2D;
constexpr GLenum kContextCompatibilityProfile = GL_CONTEXT_COMPATIBILITY_PROFILE_BIT;

// GLSL 1.50 compatibility (OpenGL 3.2): with the primitive id. GLSL 1.20: without (0).
const char* const kVertex150 =
    "#version 150 compatibility\n"
    "void main() {\n"
    "  gl_Position = ftransform();\n"
    "  gl_ClipVertex = gl_ModelViewMatrix * gl_Vertex;\n"
    "}\n";
const char* const kFragment150 =
    "#version 150 compatibility\n"
    "uniform float viper_draw_id;\n"
    "out vec4 viper_id_out;\n"
    "void main() { viper_id_out = vec4(viper_draw_id, float(gl_PrimitiveID), 0.0, 1.0); }\n";
const char* const kVertex120 =
    "#version 120\n"
    "void main() {\n"
    "  gl_Position = ftransform();\n"
    "  gl_ClipVertex = gl_ModelViewMatrix * gl_Vertex;\n"
    "}\n";
const char* const kFragment120 =
    "#version 120\n"
    "uniform float viper_draw_id;\n"
    "void main() { gl_FragData[7] = vec4(viper_draw_id, 0.0, 0.0, 1.0); }\n";

// Whether a shader compiled or a program linked (`status` of `object`, read with `get`); if not,
// `log` gets its info log (read with `info_log`).
bool built(GLuint object, GLenum status, PFNGLGETSHADERIVPROC get, PFNGLGETSHADERINFOLOGPROC info_log,
           std::string& log) {
  GLint ok = 0;
  get(object, status, &ok);
  if (ok) return true;
  char text[512] = {0};
  info_log(object, sizeof(text), nullptr, text);
  log = text;
  return false;
}

GLuint compile(const RealGl& g, GLenum type, const char* source, std::string& log) {
  const GLuint shader = g.CreateShader(type);
  g.ShaderSource(shader, 1, &source, nullptr);
  g.CompileShader(shader);
  if (!built(shader, GL_COMPILE_STATUS, g.GetShaderiv, g.GetShaderInfoLog, log)) {
    g.DeleteShader(shader);
    return 0;
  }
  return shader;
}

}  // namespace

void Interceptor::noteFixedFunction(ContextState& c) {
  c.fixed_function_noted = true;
  // (GL_CONTEXT_PROFILE_MASK is OpenGL 3.2; 3.1 has the fixed function only with ARB_compatibility.)
  if (glVersionAtLeast(3, 2)) c.fixed_function = (glInt(GL_CONTEXT_PROFILE_MASK) & kContextCompatibilityProfile) != 0;
  else c.fixed_function = !glVersionAtLeast(3, 1) || glHasExtension("GL_ARB_compatibility");
  c.counting_queries.clear();
  if (!c.fixed_function) return;
  c.program_pipelines = glVersionAtLeast(4, 1) || glHasExtension("GL_ARB_separate_shader_objects");
  c.arb_vertex_programs = glHasExtension("GL_ARB_vertex_program");
  // Each target is asked only where the GL has it (asking of another is an error the program would read).
  if (glVersionAtLeast(1, 5)) c.counting_queries.push_back(GL_SAMPLES_PASSED);
  if (glVersionAtLeast(3, 0)) c.counting_queries.push_back(GL_PRIMITIVES_GENERATED);
  if (glVersionAtLeast(3, 3)) c.counting_queries.push_back(GL_ANY_SAMPLES_PASSED);
  if (glVersionAtLeast(4, 3)) c.counting_queries.push_back(GL_ANY_SAMPLES_PASSED_CONSERVATIVE);
  if (glVersionAtLeast(4, 6) || glHasExtension("GL_ARB_pipeline_statistics_query"))
    for (GLenum q : {0x82EEu, 0x82EFu, 0x82F0u, 0x82F1u, 0x82F2u, 0x82F3u, 0x82F4u, 0x82F6u, 0x82F7u, 0x887Fu})
      c.counting_queries.push_back(q);  // vertices and primitives submitted, shader invocations, clipping
}

void Interceptor::clearIdsUnderFixedFunction(FrameTarget* t, FrameTarget::ProgramFbo* scene_fbo, bool writes_depth) {
  const RealGl& g = gl();
  // Through blending (ZERO, ZERO) on our buffer alone, so that no pixel keeps the id of what lies
  // behind under its depth. (Per-buffer blend functions are GL 4.0: before it, such draws leave
  // the ids as they are.)
  const bool clears = writes_depth && g.BlendFuncSeparatei && g.BlendEquationi;
  t->wantIds(scene_fbo, clears);
  if (!clears) return;
  g.Enablei(GL_BLEND, kIdDrawBuffer);
  g.BlendFuncSeparatei(kIdDrawBuffer, GL_ZERO, GL_ZERO, GL_ZERO, GL_ZERO);
  g.BlendEquationi(kIdDrawBuffer, GL_FUNC_ADD);
  if (!cx().ids_write) {
    g.ColorMaski(kIdDrawBuffer, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    cx().ids_write = true;
  }
  cx().blend_dirty = true;  // the next draw with a program writes its ids unblended again
}

bool Interceptor::beforeFixedFunctionDraw(const DrawCall& call, FrameTarget* t, FrameTarget::ProgramFbo* scene_fbo) {
  ContextState& c = cx();
  c.id_pass_value = 0.0f;
  if (!scene_fbo && t->sceneEnded()) {  // after the scene (endScene): nothing recorded, ids off
    t->wantIds(nullptr, false);
    return false;
  }
  const RealGl& g = gl();
  const DepthUse depth = depthUse(g);
  clearIdsUnderFixedFunction(t, scene_fbo, depth.writes);
  if (c.compiling_list) return notRecordedInList();
  const ProgramInfo& p = fixed_function_;
  if (p.overlay) return false;  // the profile says: 2D overlay
  // Not recorded: in a context without the fixed function (a core profile draws nothing without a
  // program), and without the depth test (2D drawing: text, HUD, backdrops).
  if (!c.fixed_function || g.IsEnabled(GL_DEPTH_TEST) != GL_TRUE) {
    ++c.frame.unrecorded_draws;
    if (c.fixed_function) logOnce("draws without a program and without depth test (2D) are not recorded (each counted among the frame's draws not recorded)");
    return false;
  }
  // Not the fixed-function pipeline, and nothing the layer reads of it: a program the layer does
  // not know, a program pipeline's draw (glBindProgramPipeline, program 0), or one an ARB vertex
  // program transforms.
  // A program the layer did not see linked (program 0 is the fixed function) is drawn as it is.
  const char* other = nullptr;
  if (c.current_program != 0)
    other = "draws with a program the layer did not see linked are not recorded (each counted among the frame's draws not recorded)";
  else if (c.program_pipelines && glInt(GL_PROGRAM_PIPELINE_BINDING) != 0)
    other = "draws with a program pipeline (separable programs) are not recorded (each counted among the frame's draws not recorded)";
  else if (c.arb_vertex_programs && g.IsEnabled(kVertexProgramArb) == GL_TRUE)
    other = "draws transformed by an ARB vertex program are not recorded (each counted among the frame's draws not recorded)";
  if (other && !getenv("VIPER_DEBUG_NO_OTHER")) {
    ++c.frame.unrecorded_draws;  // (its ids cleared where it writes depth, as above)
    logOnce(other);
    return false;
  }
  if (scene_fbo) ++scene_fbo->draws;
  const uint32_t index = static_cast<uint32_t>(c.frame.draws.size());
  c.frame.draws.emplace_back();
  DrawRecord& r = c.frame.draws.back();
  r.index = index;
  r.program_key = p.key;
  r.primitive_mode = call.mode;
  r.primitive_count = primitiveCount(call.mode, static_cast<size_t>(call.count)) * static_cast<uint32_t>(call.instances);
  if (p.matrix_stack) {
    readMatrixStack(r, p.stack_push_world);
  } else {
    g.GetFloatv(VIPER_GL_PROJECTION_MATRIX, r.projection.data());
    r.matrix_flags |= kHasProjection;
  }
  if (combines_ && !p.matrix_stack) {  // the stack's model-view, a combined matrix (camera_recovery.h)
    DrawMatrices combined;
    g.GetFloatv(VIPER_GL_MODELVIEW_MATRIX, combined.model_view.data());
    combined.known = kMatModelView;
    keepDrawMatrices(p, r, combined);
  }
  if (!p.combined) finishMatrices(p.expected_matrices, r);
  // The texture of unit 0 (what a fixed-function draw's look mostly comes from), where enabled.
  if (c.active_unit == 0 && g.IsEnabled(kTexture2d) == GL_TRUE) r.texture_keys.push_back(textureKey(kTexture2d, 0));
  if (!call.immediate) {  // (glBegin: at glEnd, endImmediate)
    recordMesh(call, p, r);
    if (!r.mesh_key) r.gaps |= kGapNoMesh;
  }
  c.last_recorded = true;
  if (!depth.writes) return true;  // an effect (no depth written): no pixel's id, as with programs
  bool counting = false;
  for (GLenum q : c.counting_queries) {
    GLint active = 0;
    g.GetQueryiv(q, GL_CURRENT_QUERY, &active);
    counting = counting || active != 0;
  }
  if (counting || t->programOwnsIdDrawBuffer() || !idProgram()) {
    r.gaps |= kGapNoIds;
    if (counting) logOnce("draws without a program made while a query counts samples or primitives get no ids (an id pass would count in the query)");
    return true;
  }
  c.id_pass_value = static_cast<float>(index + 1);
  return true;
}

void Interceptor::beginImmediate(GLenum mode) {
  ContextState& c = cx();
  c.immediate.active = false;
  if (currentProgram()) return beforeUnrecordableDraw("immediate-mode (glBegin/glEnd) with a program");
  DrawCall call;
  call.mode = mode;
  call.immediate = true;
  if (!beforeDraw(call)) return;
  c.immediate.active = true;
  c.immediate.mode = mode;
  c.immediate.record = static_cast<uint32_t>(c.frame.draws.size() - 1);
  c.immediate.vertices.clear();
}

void Interceptor::endImmediate() {
  ContextState& c = cx();
  if (!c.immediate.active) return;
  c.immediate.active = false;
  const std::vector<float>& v = c.immediate.vertices;
  const size_t n = v.size() / 4;
  DrawRecord& r = c.frame.draws[c.immediate.record];
  r.primitive_count = primitiveCount(c.immediate.mode, n);
  // The mesh from the vertices as passed (x, y, z over w: glVertex4 may give w other than 1).
  std::vector<float> xyz(n * 3);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) xyz[i * 3 + k] = v[i * 4 + k] / v[i * 4 + 3];
  PositionLayout layout;
  layout.size = 3;
  layout.type = GL_FLOAT;
  DrawRange range;
  range.mode = c.immediate.mode;
  range.count = n;
  ExtractedMesh mesh;
  if (extractMesh(reinterpret_cast<const uint8_t*>(xyz.data()), xyz.size() * sizeof(float), layout, range, mesh)) {
    mirrorForProfile(mesh);
    r.mesh_key = mesh.mesh.key;
    std::lock_guard<std::mutex> lock(mutex_);
    if (emitted_meshes_.insert(mesh.mesh.key).second) c.frame.new_meshes.push_back(mesh.mesh);
  } else {
    r.gaps |= kGapNoMesh;
  }
  if (!beginIdPass()) return;
  const RealGl& g = gl();
  g.Begin(c.immediate.mode);
  for (size_t i = 0; i < n; ++i) g.Vertex4fv(&v[i * 4]);
  g.End();
  endIdPass();
}

GLuint Interceptor::idProgram() {
  ContextState& c = cx();
  if (c.id_program || c.id_program_failed) return c.id_program;
  const RealGl& g = gl();
  const bool glsl150 = glVersionAtLeast(3, 2);
  std::string log;
  const GLuint vs = compile(g, GL_VERTEX_SHADER, glsl150 ? kVertex150 : kVertex120, log);
  const GLuint fs = vs ? compile(g, GL_FRAGMENT_SHADER, glsl150 ? kFragment150 : kFragment120, log) : 0;
  GLuint program = 0;
  if (vs && fs) {
    program = g.CreateProgram();
    g.AttachShader(program, vs);
    g.AttachShader(program, fs);
    if (glsl150) g.BindFragDataLocation(program, kIdOutputLocation, kIdOutputName);
    g.LinkProgram(program);
    // (A program that does not link is left to the context: deleting needs glDeleteProgram, a
    // name it never sees.)
    if (!built(program, GL_LINK_STATUS, g.GetProgramiv, g.GetProgramInfoLog, log)) program = 0;
  }
  if (vs) g.DeleteShader(vs);
  if (fs) g.DeleteShader(fs);
  if (!program) {
    c.id_program_failed = true;
    logOnce("the id program for draws without a program does not build (" + log + "): they get no ids");
    return 0;
  }
  c.id_program = program;
  c.id_program_draw_id = g.GetUniformLocation(program, kDrawIdUniform);
  return program;
}

bool Interceptor::notRecordedInList() {
  // Made with GL_COMPILE_AND_EXECUTE, the draw also runs now: counted.
  if (cx().compiling_list != 0x1300) ++cx().frame.unrecorded_draws;
  logOnce("draws made while a display list is being made are not recorded (those that run are counted among the "
          "frame's draws not recorded)");
  return false;
}

bool Interceptor::beginIdPass() {
  ContextState& c = cx();
  if (c.id_pass_value == 0.0f || getenv("VIPER_DEBUG_NO_IDPASS")) { c.id_pass_value = 0.0f; return false; }
  const RealGl& g = gl();
  ContextState::IdPassSaved& s = c.id_pass_saved;
  for (GLuint i = 0; i < kIdDrawBuffer; ++i) {
    g.GetBooleani_v(GL_COLOR_WRITEMASK, i, s.color_masks[i]);
    g.ColorMaski(i, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  }
  // Our buffer written as it is, unblended (the draw itself cleared it: clearIdsUnderFixedFunction).
  g.Disablei(GL_BLEND, kIdDrawBuffer);
  c.blend_dirty = true;
  s.depth_func = glInt(GL_DEPTH_FUNC);
  g.DepthFunc(GL_EQUAL);
  g.DepthMask(GL_FALSE);
  // The stencil test could pass where the draw wrote stencil; the alpha test would read our
  // program's undefined colour. Equal depth alone says where the draw's fragments are.
  s.stencil_test = g.IsEnabled(GL_STENCIL_TEST) == GL_TRUE;
  if (s.stencil_test) g.Disable(GL_STENCIL_TEST);
  s.alpha_test = g.IsEnabled(kAlphaTest) == GL_TRUE;
  if (s.alpha_test) g.Disable(kAlphaTest);
  g.UseProgram(c.id_program);
  g.Uniform1f(c.id_program_draw_id, c.id_pass_value);
  return true;
}

void Interceptor::endIdPass() {
  ContextState& c = cx();
  const RealGl& g = gl();
  const ContextState::IdPassSaved& s = c.id_pass_saved;
  g.UseProgram(0);
  if (s.alpha_test) g.Enable(kAlphaTest);
  if (s.stencil_test) g.Enable(GL_STENCIL_TEST);
  g.DepthMask(GL_TRUE);
  g.DepthFunc(static_cast<GLenum>(s.depth_func));
  for (GLuint i = 0; i < kIdDrawBuffer; ++i)
    g.ColorMaski(i, s.color_masks[i][0], s.color_masks[i][1], s.color_masks[i][2], s.color_masks[i][3]);
  c.id_pass_value = 0.0f;
}

}  // namespace capture
}  // namespace viper
