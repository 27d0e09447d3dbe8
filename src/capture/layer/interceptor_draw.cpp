// Per-draw work: draw ids, matrices, content keys, meshes and deformed vertices.
#include "interceptor.h"

#include "viper/capture/content_key.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

namespace viper {
namespace capture {

namespace {

GLint vertexAttrib(GLuint index, GLenum pname) {
  GLint v = 0;
  gl().GetVertexAttribiv(index, pname, &v);
  return v;
}

// Everything a mesh extraction depends on, hashed as one cache key.
struct MeshCacheKey {
  uint64_t vbo, vbo_version, ibo, ibo_version;
  uint64_t offset, stride, index_offset;
  int64_t first, base_vertex, count;
  uint32_t size, type, mode, index_type;
};

float halfToFloat(uint16_t h) {
  const uint32_t sign = (h >> 15) & 1u, exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  float v;
  if (exponent == 0) v = std::ldexp(static_cast<float>(mantissa), -24);
  else if (exponent == 31) v = mantissa ? NAN : INFINITY;
  else v = std::ldexp(static_cast<float>(mantissa | 0x400u), static_cast<int>(exponent) - 25);
  return sign ? -v : v;
}

// Components of one attribute element of GL type `type` (float and half float; others: false).
bool decodeAttribute(const uint8_t* bytes, GLenum type, int size, float out[4]) {
  for (int i = 0; i < size; ++i) {
    if (type == GL_FLOAT) {
      std::memcpy(&out[i], bytes + 4 * i, 4);
    } else if (type == GL_HALF_FLOAT) {
      uint16_t h;
      std::memcpy(&h, bytes + 2 * i, 2);
      out[i] = halfToFloat(h);
    } else {
      return false;
    }
  }
  return true;
}

// The part of a draw's range that does not depend on where its indices are.
DrawRange drawRange(const DrawCall& call) {
  DrawRange range;
  range.mode = call.mode;
  range.count = static_cast<size_t>(call.count);
  range.first = call.first;
  range.base_vertex = call.base_vertex;
  range.index_type = call.indexed ? call.index_type : 0;
  return range;
}

}  // namespace

DepthUse depthUse(const RealGl& g) {
  GLboolean mask = GL_FALSE;
  g.GetBooleanv(GL_DEPTH_WRITEMASK, &mask);
  const bool test = g.IsEnabled(GL_DEPTH_TEST) == GL_TRUE;
  DepthUse d;
  d.writes = mask == GL_TRUE && test;
  d.shades_decided = mask == GL_FALSE && test && glInt(GL_DEPTH_FUNC) == GL_EQUAL;
  return d;
}

void Interceptor::mirrorForProfile(ExtractedMesh& mesh) const {
  if (!profile_.left_handed) return;  // the mirror image in z (capture_profile.h)
  std::vector<float>& xyz = mesh.mesh.positions_xyz;
  for (size_t i = 2; i < xyz.size(); i += 3) xyz[i] = -xyz[i];
}

bool Interceptor::readMatrix(const MatrixSource& m, GlMatrix& out) {
  const RealGl& g = gl();
  if (m.location >= 0) {
    g.GetUniformfv(cx().current_program, m.location, out.data());  // whatever glUniform* the program used
    return true;
  }
  if (m.element_locations[0] >= 0) {  // four vec4 elements of a uniform array: rows or columns
    for (int v = 0; v < 4; ++v) {
      float vec[4];
      g.GetUniformfv(cx().current_program, m.element_locations[v], vec);
      for (int k = 0; k < 4; ++k) (m.row_major ? out(v, k) : out(k, v)) = vec[k];
    }
    return true;
  }
  if (m.block == GL_INVALID_INDEX) return false;
  GLint binding = 0, buffer = 0;
  GLint64 start = 0;
  g.GetActiveUniformBlockiv(cx().current_program, m.block, GL_UNIFORM_BLOCK_BINDING, &binding);
  g.GetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, static_cast<GLuint>(binding), &buffer);
  g.GetInteger64i_v(GL_UNIFORM_BUFFER_START, static_cast<GLuint>(binding), &start);
  if (buffer == 0 || m.matrix_stride < 16 || m.matrix_stride > 64) return false;
  // Four columns (rows if row-major) of 16 bytes, matrix_stride apart: one read of the span.
  uint8_t bytes[4 * 64];
  const size_t span = 3 * static_cast<size_t>(m.matrix_stride) + 16;
  if (!readBufferBytes(static_cast<GLuint>(buffer), static_cast<size_t>(start) + static_cast<size_t>(m.offset), span, bytes))
    return false;
  for (int v = 0; v < 4; ++v) {
    float vec[4];
    std::memcpy(vec, bytes + v * m.matrix_stride, sizeof(vec));
    for (int k = 0; k < 4; ++k) (m.row_major ? out(v, k) : out(k, v)) = vec[k];
  }
  return true;
}

bool Interceptor::readAttribute(GLint location, const DrawCall& call, float out[4]) {
  const GLuint a = static_cast<GLuint>(location);
  if (!vertexAttrib(a, GL_VERTEX_ATTRIB_ARRAY_ENABLED)) return false;
  const GLint divisor = vertexAttrib(a, GL_VERTEX_ATTRIB_ARRAY_DIVISOR);
  const GLuint buffer = static_cast<GLuint>(vertexAttrib(a, GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING));
  if (divisor <= 0 || !buffer) return false;  // not an instanced attribute in a buffer object
  const int size = vertexAttrib(a, GL_VERTEX_ATTRIB_ARRAY_SIZE);
  const GLenum type = static_cast<GLenum>(vertexAttrib(a, GL_VERTEX_ATTRIB_ARRAY_TYPE));
  const size_t component = type == GL_HALF_FLOAT ? 2 : 4;
  size_t stride = static_cast<size_t>(vertexAttrib(a, GL_VERTEX_ATTRIB_ARRAY_STRIDE));
  if (stride == 0) stride = component * static_cast<size_t>(size);
  void* pointer = nullptr;
  gl().GetVertexAttribPointerv(a, GL_VERTEX_ATTRIB_ARRAY_POINTER, &pointer);
  const size_t element = call.base_instance;  // instance 0 of the draw (split draws: one instance)
  uint8_t bytes[16];
  if (size < 1 || size > 4 ||
      !readBufferBytes(buffer, reinterpret_cast<size_t>(pointer) + element * stride, component * size, bytes))
    return false;
  out[0] = out[1] = out[2] = 0.0f;
  out[3] = 1.0f;
  return decodeAttribute(bytes, type, size, out);
}

bool Interceptor::readInstanceWorld(const InstanceTransform& t, const DrawCall& call, GlMatrix& out) {
  float v[4];
  if (t.world >= 0) {
    for (int c = 0; c < 4; ++c) {
      if (!readAttribute(t.world + c, call, v)) return false;
      out.col(c) = Eigen::Vector4f(v[0], v[1], v[2], v[3]);
    }
    return true;
  }
  Eigen::Affine3f m = Eigen::Affine3f::Identity();
  if (t.translation >= 0) {
    if (!readAttribute(t.translation, call, v)) return false;
    m.translate(Eigen::Vector3f(v[0], v[1], v[2]));
  }
  if (t.rotation >= 0) {
    if (!readAttribute(t.rotation, call, v)) return false;
    Eigen::Quaternionf q(v[3], v[0], v[1], v[2]);
    if (q.norm() < 1e-6f) return false;
    q.normalize();
    m.rotate(t.rotation_conjugate ? q.conjugate() : q);
  }
  if (t.scale >= 0) {
    if (!readAttribute(t.scale, call, v)) return false;
    m.scale(Eigen::Vector3f(v[0], v[1], v[2]));
  }
  out = m.matrix();
  return true;
}

bool Interceptor::recordable() {
  FrameTarget* t = target();
  if (!enabled_ || !t || !t->ready()) return false;
  if (t->program_draw_fb != 0 && !t->sceneFbo()) return false;
  ProgramInfo* p = currentProgram();
  return p && !p->overlay;
}

bool Interceptor::splitsInstances(const DrawCall& call) {
  if (call.instances <= 1 || !cx().base_instance_draws || !recordable()) return false;
  const ProgramInfo* p = currentProgram();
  if (!p->rewritten || p->reads_draw_parameters) return false;
  const GLint attributes = glInt(GL_MAX_VERTEX_ATTRIBS);
  for (GLint a = 0; a < attributes; ++a) {
    if (!vertexAttrib(static_cast<GLuint>(a), GL_VERTEX_ATTRIB_ARRAY_ENABLED)) continue;
    if (vertexAttrib(static_cast<GLuint>(a), GL_VERTEX_ATTRIB_ARRAY_DIVISOR) > 1) return false;
  }
  return true;
}

bool Interceptor::decomposesMultiDraw() {
  if (!recordable()) return false;
  const ProgramInfo* p = currentProgram();
  return p->rewritten && !p->reads_draw_parameters;
}

void Interceptor::beforeUndecomposedDraw(const char* what) {
  FrameTarget* t = target();
  if (!enabled_ || !t || !t->ready()) return;
  ProgramInfo* p = currentProgram();
  const bool into_scene = t->program_draw_fb == 0 ? !t->sceneEnded() : t->sceneFbo() != nullptr;
  if (into_scene && !(p && p->overlay)) ++cx().frame.unrecorded_draws;
  if (recordable() && p && p->rewritten) {
    char key[32];
    std::snprintf(key, sizeof(key), "%016llx", static_cast<unsigned long long>(p->key));
    logOnce(std::string(what) + " of program " + key + ", whose shaders read gl_DrawID: drawn whole, not recorded");
  }
  // Whatever the uniform holds would name another draw: no ids from this one.
  if (t->program_draw_fb == 0) t->wantIds(nullptr, false);
  else if (FrameTarget::ProgramFbo* f = t->sceneFbo()) t->wantIds(f, false);
}

void Interceptor::beforeUnrecordableDraw(const char* what) {
  FrameTarget* t = target();
  if (!enabled_ || !t || !t->ready()) return;
  FrameTarget::ProgramFbo* scene_fbo = nullptr;
  if (t->program_draw_fb != 0 && !(scene_fbo = t->sceneFbo())) return;
  ProgramInfo* p = currentProgram();
  if (!p) {  // as a draw without a program that is not recorded
    if (!scene_fbo && t->sceneEnded()) {
      t->wantIds(nullptr, false);
    } else {
      ++cx().frame.unrecorded_draws;
      clearIdsUnderFixedFunction(t, scene_fbo, depthUse(gl()).writes);
    }
  } else if (!p->overlay && (scene_fbo || !t->sceneEnded())) {
    ++cx().frame.unrecorded_draws;
    t->wantIds(scene_fbo, false);
  }
  logOnce(std::string(what) + " draws are not recorded (each counted among the frame's draws not recorded)");
}

bool Interceptor::readIndirect(size_t offset, void* out, size_t size) {
  const GLuint buffer = static_cast<GLuint>(glInt(GL_DRAW_INDIRECT_BUFFER_BINDING));
  return buffer && readBufferBytes(buffer, offset, size, out);
}

void Interceptor::setDrawId(float value) {
  // (Set at every draw, never skipped as unchanged: programs of unshared contexts may share a
  // name, and so what the layer knows of them.)
  ProgramInfo* p = currentProgram();
  if (p && p->loc_draw_id >= 0) gl().Uniform1f(p->loc_draw_id, value);
}

bool Interceptor::beforeDraw(const DrawCall& call) {
  cx().last_recorded = false;
  cx().last_mesh = false;
  FrameTarget* t = target();
  if (!enabled_ || !t || !t->ready()) return false;
  // Recorded: draws into the default framebuffer, and into a framebuffer object that may hold the
  // scene (frame_target.h, ProgramFbo).
  FrameTarget::ProgramFbo* scene_fbo = nullptr;
  // Into a framebuffer whose draw buffer 7 is the program's own: viper_draw_id 0, so that a
  // rewritten shader writes it as the original would (gl_FragColor to every buffer). (Only then:
  // the uniform belongs to the program, which other contexts may be drawing with.)
  if (t->programOwnsIdDrawBuffer()) setDrawId(0.0f);
  if (t->program_draw_fb != 0 && !(scene_fbo = t->sceneFbo())) return false;
  return beforeSceneDraw(call, t, scene_fbo);
}

bool Interceptor::beforeSceneDraw(const DrawCall& call, FrameTarget* t, FrameTarget::ProgramFbo* scene_fbo) {
  ProgramInfo* p = currentProgram();
  if (!p) return beforeFixedFunctionDraw(call, t, scene_fbo);
  const RealGl& g = gl();
  // After the scene ended (endScene) nothing is recorded: ids off.
  const bool scene_ended = !scene_fbo && t->sceneEnded();
  t->wantIds(scene_fbo, !scene_ended && p->rewritten);
  if (scene_ended) return false;
  if (cx().compiling_list) return notRecordedInList();
  if (scene_fbo) ++scene_fbo->draws;
  if (p->overlay) {  // the 2D overlay: ids off (above), not recorded, not in the frame's color
    if (!scene_fbo) t->snapshotSceneColor();
    return false;
  }
  if (cx().blend_dirty) {
    // Ids are written unblended, whatever the program's blending (glEnable(GL_BLEND) enables it
    // for every draw buffer, ours included): a blended id would be no id at all.
    g.Disablei(GL_BLEND, kIdDrawBuffer);
    cx().blend_dirty = false;
  }
  const uint32_t index = static_cast<uint32_t>(cx().frame.draws.size());
  if (p->rewritten) {
    // An id always names the surface the depth image holds. A blended draw that writes no depth
    // (its mask off, or no depth test) is an effect (rain, glare, smoke): it takes no pixel's id
    // whatever its alpha. One that writes depth writes its id where its fragments are mostly
    // opaque, and id 0 (no object) where they are mostly transparent (shader_rewrite.h).
    // A pass at equal depth with depth writes off (a depth pre-pass engine's colour pass, with
    // its colour mask on again) leaves the ids of the pass that wrote the depth. (The program's
    // colour mask never covers ours: colorMaskChanged.)
    const DepthUse depth = depthUse(g);
    const bool write_ids = (!cx().blend0_enabled || depth.writes) && !depth.shades_decided;
    if (write_ids != cx().ids_write) {
      const GLboolean m = write_ids ? GL_TRUE : GL_FALSE;
      g.ColorMaski(kIdDrawBuffer, m, m, m, m);
      cx().ids_write = write_ids;
    }
    setDrawId(t->programOwnsIdDrawBuffer() ? 0.0f : static_cast<float>(index + 1));
    const float alpha_test = cx().blend0_enabled ? 1.0f : 0.0f;
    if (alpha_test != p->alpha_test_value) {
      g.Uniform1f(p->loc_alpha_test, alpha_test);
      p->alpha_test_value = alpha_test;
    }
  }

  cx().frame.draws.emplace_back();
  DrawRecord& r = cx().frame.draws.back();
  r.index = index;
  r.program_key = p->key;
  r.primitive_mode = call.mode;
  r.primitive_count = primitiveCount(call.mode, static_cast<size_t>(call.count)) * static_cast<uint32_t>(call.instances);
  if (p->matrix_stack) {
    readMatrixStack(r, p->stack_push_world);
  } else if (p->instance.any()) {
    if (readInstanceWorld(p->instance, call, r.world)) r.matrix_flags |= kHasWorld;
  } else if (p->world.found() && readMatrix(p->world, r.world)) {
    r.matrix_flags |= kHasWorld;
  }
  if (p->view.found() && readMatrix(p->view, r.view)) r.matrix_flags |= kHasView;
  if (p->projection.found() && readMatrix(p->projection, r.projection)) {
    r.matrix_flags |= kHasProjection;
    toGlClipDepth(r.projection);
  }
  if (combines_) {
    DrawMatrices combined;
    if (p->model_view.found() && readMatrix(p->model_view, combined.model_view)) combined.known |= kMatModelView;
    if (p->view_projection.found() && readMatrix(p->view_projection, combined.view_projection)) {
      combined.known |= kMatViewProjection;
      toGlClipDepth(combined.view_projection);
    }
    if (p->model_view_projection.found() && readMatrix(p->model_view_projection, combined.model_view_projection)) {
      combined.known |= kMatModelViewProjection;
      toGlClipDepth(combined.model_view_projection);
    }
    keepDrawMatrices(*p, r, combined);
  }
  if (!p->combined) finishMatrices(p->expected_matrices, r);
  if (!p->rewritten) r.gaps |= kGapNoIds;
  for (size_t i = 0; i < p->sampler_locations.size(); ++i) {
    GLint unit = 0;
    g.GetUniformiv(cx().current_program, p->sampler_locations[i], &unit);
    r.texture_keys.push_back(textureKey(p->sampler_targets[i], static_cast<GLuint>(unit)));
  }
  recordMesh(call, *p, r);
  if (!r.mesh_key) r.gaps |= kGapNoMesh;
  cx().last_recorded = true;
  return true;
}

void Interceptor::toGlClipDepth(GlMatrix& projection) const {
  if (!profile_.clip_depth_zero_to_one) return;
  // Dz P (capture_profile.h): clip z' = 2 z - w, as the program's own conversion after it does.
  projection.row(2) = 2.0f * projection.row(2) - projection.row(3);
}

void Interceptor::finishMatrices(uint8_t expected_matrices, DrawRecord& r) const {
  if (profile_.left_handed) {  // the mirror image in z, in OpenGL's conventions (capture_profile.h)
    const Eigen::Vector4f f(1.0f, 1.0f, -1.0f, 1.0f);
    if (r.matrix_flags & kHasWorld) r.world = f.asDiagonal() * r.world * f.asDiagonal();
    if (r.matrix_flags & kHasView) r.view = f.asDiagonal() * r.view * f.asDiagonal();
    if (r.matrix_flags & kHasProjection) r.projection = r.projection * f.asDiagonal();
  }
  if (expected_matrices & ~r.matrix_flags) r.gaps |= kGapMatrixMissing;
}

void Interceptor::keepDrawMatrices(const ProgramInfo& p, const DrawRecord& r, const DrawMatrices& combined) {
  ContextState::DrawMatricesEntry e{r.index, p.combined, p.expected_matrices, combined};
  DrawMatrices& m = e.matrices;
  if (r.matrix_flags & kHasWorld) m.world = r.world, m.known |= kMatWorld;
  if (r.matrix_flags & kHasView) m.view = r.view, m.known |= kMatView;
  if (r.matrix_flags & kHasProjection) m.projection = r.projection, m.known |= kMatProjection;
  if (p.world_space) m.known |= kMatWorldSpace;
  if (m.known) cx().frame_matrices.push_back(e);
}

void Interceptor::resolveCombined() {
  std::vector<ContextState::DrawMatricesEntry>& kept = cx().frame_matrices;
  bool deferred = false;
  for (const auto& e : kept) deferred = deferred || e.deferred;
  if (!deferred) {
    kept.clear();
    return;
  }
  std::vector<DrawMatrices> draws;
  draws.reserve(kept.size());
  for (const auto& e : kept) draws.push_back(e.matrices);
  const FrameCameraResult camera = resolveFrameMatrices(draws);
  for (size_t k = 0; k < kept.size(); ++k) {
    if (!kept[k].deferred) continue;
    DrawRecord& r = cx().frame.draws[kept[k].index];
    const DrawMatrices& m = draws[k];
    if (m.known & kMatWorld) r.world = m.world, r.matrix_flags |= kHasWorld;
    if (m.known & kMatView) r.view = m.view, r.matrix_flags |= kHasView;
    if (m.known & kMatProjection) r.projection = m.projection, r.matrix_flags |= kHasProjection;
    finishMatrices(kept[k].expected, r);
  }
  if (camera.ok) logOnce("the frame's camera from combined matrices: " + camera.source);
  else logOnce("no camera recovered from the combined matrices (draws keep what they gave, without world): " + camera.why);
  if (camera.inconsistent_draws > 0)
    logOnce("draws whose matrices disagree with the frame's camera (another pass: shadow, reflection, a weapon's own "
            "field of view) keep their own view or projection");
  kept.clear();
}

void Interceptor::readMatrixStack(DrawRecord& r, bool push_world) {
  const RealGl& g = gl();
  GlMatrix modelview;
  g.GetFloatv(VIPER_GL_PROJECTION_MATRIX, r.projection.data());
  g.GetFloatv(VIPER_GL_MODELVIEW_MATRIX, modelview.data());
  r.matrix_flags |= kHasProjection;
  const GlMatrix product = cx().modelview.view() * cx().modelview.world();
  const float scale = std::max(1.0f, modelview.cwiseAbs().maxCoeff());
  if ((product - modelview).cwiseAbs().maxCoeff() > 1e-4f * scale) {
    logOnce("the model-view matrix is not what the layer tracked of the stack (glLoadMatrix, glMultMatrix...; "
            "matrix_stack): draws so made are recorded without world and view");
    return;
  }
  if (push_world) {  // the camera: what the bottom of the stack holds; the world: what is above it
    r.view = cx().modelview.base();
    r.world = r.view.inverse() * product;
  } else {
    r.world = cx().modelview.world();
    r.view = cx().modelview.view();
  }
  r.matrix_flags |= kHasWorld | kHasView;
  cx().stack_draws.push_back(r.index);
}

void Interceptor::oneStackView() {
  if (cx().stack_draws.size() < 2) {
    cx().stack_draws.clear();
    return;
  }
  std::map<std::vector<float>, size_t> counts;
  for (uint32_t i : cx().stack_draws) {
    const GlMatrix& v = cx().frame.draws[i].view;
    ++counts[std::vector<float>(v.data(), v.data() + 16)];
  }
  auto best = counts.begin();
  for (auto it = counts.begin(); it != counts.end(); ++it)
    if (it->second > best->second) best = it;
  const GlMatrix view = Eigen::Map<const GlMatrix>(best->first.data());
  const GlMatrix inverse = view.inverse();
  for (uint32_t i : cx().stack_draws) {
    DrawRecord& d = cx().frame.draws[i];
    if (d.view == view) continue;
    d.world = inverse * d.view * d.world;
    d.view = view;
  }
  cx().stack_draws.clear();
}

void Interceptor::recordMesh(const DrawCall& call, const ProgramInfo& p, DrawRecord& r) {
  const RealGl& g = gl();
  PositionLayout layout;
  void* pointer = nullptr;
  GLuint vbo = 0;
  if (p.vertex_array_position) {  // gl_Vertex: the conventional array, in a buffer or client memory
    if (!g.IsEnabled(VIPER_GL_VERTEX_ARRAY)) return;
    layout.size = glInt(VIPER_GL_VERTEX_ARRAY_SIZE);
    layout.type = static_cast<unsigned>(glInt(VIPER_GL_VERTEX_ARRAY_TYPE));
    layout.stride = static_cast<size_t>(glInt(VIPER_GL_VERTEX_ARRAY_STRIDE));
    g.GetPointerv(VIPER_GL_VERTEX_ARRAY_POINTER, &pointer);
    vbo = static_cast<GLuint>(glInt(VIPER_GL_VERTEX_ARRAY_BUFFER_BINDING));
  } else {
    if (p.position_attrib < 0) return;
    const GLuint attrib = static_cast<GLuint>(p.position_attrib);
    if (!vertexAttrib(attrib, GL_VERTEX_ATTRIB_ARRAY_ENABLED)) return;
    vbo = static_cast<GLuint>(vertexAttrib(attrib, GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING));
    layout.size = vertexAttrib(attrib, GL_VERTEX_ATTRIB_ARRAY_SIZE);
    layout.type = static_cast<unsigned>(vertexAttrib(attrib, GL_VERTEX_ATTRIB_ARRAY_TYPE));
    layout.stride = static_cast<size_t>(vertexAttrib(attrib, GL_VERTEX_ATTRIB_ARRAY_STRIDE));
    g.GetVertexAttribPointerv(attrib, GL_VERTEX_ATTRIB_ARRAY_POINTER, &pointer);
  }
  GLint ibo = 0;
  if (call.indexed) g.GetIntegerv(GL_ELEMENT_ARRAY_BUFFER_BINDING, &ibo);
  if (vbo) layout.offset = reinterpret_cast<size_t>(pointer);
  // Client-side arrays (compatibility contexts only): vertices or indices in the program's memory.
  if (!vbo || (call.indexed && !ibo)) {
    if (!vbo && !pointer) return;
    recordClientMesh(call, layout, vbo, vbo ? nullptr : static_cast<const uint8_t*>(pointer),
                     static_cast<GLuint>(ibo), r);
    return;
  }

  std::lock_guard<std::mutex> lock(mutex_);
  auto vb = buffers_.find(vbo);
  if (vb == buffers_.end()) return;
  auto ib = buffers_.find(static_cast<GLuint>(ibo));
  if (call.indexed && ib == buffers_.end()) return;
  const BufferShadow& vertices = vb->second;
  if (vertices.map_pointer && vertices.map_persistent) {
    // Vertices in a persistent mapping: the program rewrites that memory without telling the GL
    // (a ring of regions, fenced), so our copy of the buffer is stale; the mesh is extracted from
    // the mapped memory, what the GPU reads, at every draw. The buffer has no content key then.
    if (layout.offset < vertices.map_offset) return;
    PositionLayout mapped = layout;
    mapped.offset -= vertices.map_offset;
    DrawRange range = drawRange(call);
    if (call.indexed) {
      range.index_data = ib->second.data.data();
      range.index_bytes = ib->second.data.size();
      range.index_offset = call.index_offset;
      r.index_buffer_key = bufferKey(static_cast<GLuint>(ibo));
    }
    ExtractedMesh mesh;
    if (!extractMesh(static_cast<const uint8_t*>(vertices.map_pointer), vertices.map_length, mapped, range, mesh)) return;
    mirrorForProfile(mesh);
    r.mesh_key = mesh.mesh.key;
    if (emitted_meshes_.insert(mesh.mesh.key).second) cx().frame.new_meshes.push_back(mesh.mesh);
    cx().setLastMesh(mesh);
    return;
  }
  r.vertex_buffer_key = bufferKey(vbo);
  r.index_buffer_key = call.indexed ? bufferKey(static_cast<GLuint>(ibo)) : 0;

  MeshCacheKey k;
  std::memset(&k, 0, sizeof(k));
  k.vbo = vbo;
  k.vbo_version = vb->second.version;
  k.ibo = static_cast<uint64_t>(ibo);
  k.ibo_version = call.indexed ? ib->second.version : 0;
  k.offset = layout.offset;
  k.stride = layout.stride;
  k.index_offset = call.index_offset;
  k.first = call.first;
  k.base_vertex = call.base_vertex;
  k.count = call.count;
  k.size = static_cast<uint32_t>(layout.size);
  k.type = layout.type;
  k.mode = call.mode;
  k.index_type = call.index_type;
  const uint64_t cache_key = contentKey(&k, sizeof(k));
  auto cached = mesh_cache_.find(cache_key);
  if (cached == mesh_cache_.end()) {
    ExtractedMesh mesh;
    DrawRange range = drawRange(call);
    if (call.indexed) {
      range.index_data = ib->second.data.data();
      range.index_bytes = ib->second.data.size();
      range.index_offset = call.index_offset;
    }
    if (!extractMesh(vb->second.data, layout, range, mesh)) mesh = ExtractedMesh();  // key 0: no mesh
    mirrorForProfile(mesh);
    cached = mesh_cache_.emplace(cache_key, std::move(mesh)).first;
  }
  ExtractedMesh& m = cached->second;
  r.mesh_key = m.mesh.key;
  if (m.mesh.key && emitted_meshes_.insert(m.mesh.key).second) {
    cx().frame.new_meshes.push_back(m.mesh);
    // Sent once: the cache keeps only what later frames need.
    m.mesh.positions_xyz = std::vector<float>();
    m.mesh.indices = std::vector<uint32_t>();
  }
  if (m.mesh.key) cx().setLastMesh(m);
}

void Interceptor::recordClientMesh(const DrawCall& call, const PositionLayout& layout, GLuint vbo,
                                   const uint8_t* client_vertices, GLuint ibo, DrawRecord& r) {
  DrawRange range = drawRange(call);
  std::lock_guard<std::mutex> lock(mutex_);
  const uint8_t* vertices = client_vertices;
  size_t vertex_bytes = SIZE_MAX;  // the program's memory: the draw itself reads this range
  if (vbo) {
    auto vb = buffers_.find(vbo);
    if (vb == buffers_.end()) return;
    vertices = vb->second.data.data();
    vertex_bytes = vb->second.data.size();
    r.vertex_buffer_key = bufferKey(vbo);
  }
  if (call.indexed) {
    const size_t width = call.index_type == GL_UNSIGNED_BYTE ? 1 : call.index_type == GL_UNSIGNED_SHORT ? 2 : 4;
    if (ibo) {
      auto ib = buffers_.find(ibo);
      if (ib == buffers_.end()) return;
      range.index_data = ib->second.data.data();
      range.index_bytes = ib->second.data.size();
      range.index_offset = call.index_offset;
      r.index_buffer_key = bufferKey(ibo);
    } else {
      range.index_data = reinterpret_cast<const uint8_t*>(call.index_offset);  // a pointer, not an offset
      range.index_bytes = static_cast<size_t>(call.count) * width;
      range.index_offset = 0;
    }
    if (!range.index_data) return;
  }
  ExtractedMesh mesh;
  if (!extractMesh(vertices, vertex_bytes, layout, range, mesh)) return;
  mirrorForProfile(mesh);
  r.mesh_key = mesh.mesh.key;
  if (emitted_meshes_.insert(mesh.mesh.key).second) cx().frame.new_meshes.push_back(mesh.mesh);
  cx().setLastMesh(mesh);
}

void Interceptor::afterDraw(const DrawCall& call) {
  if (!cx().last_recorded || !cx().last_mesh || !cx().current_program_info || !cx().current_program_info->deforming) return;
  const RealGl& g = gl();
  const uint32_t n = cx().last_mesh_vertices;
  GLint prev_feedback = 0, prev_buffer = 0;
  g.GetIntegerv(GL_TRANSFORM_FEEDBACK_BINDING, &prev_feedback);
  g.GetIntegerv(GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, &prev_buffer);
  if (!cx().feedback_object) g.GenTransformFeedbacks(1, &cx().feedback_object);
  const size_t slot = cx().pending_deform.size();
  if (slot >= cx().feedback_buffers.size()) {
    GLuint b = 0;
    g.GenBuffers(1, &b);
    cx().feedback_buffers.push_back(b);
  }
  const GLuint buffer = cx().feedback_buffers[slot];
  // A second pass over the mesh's vertex range, same VAO and uniforms, rasterizer off:
  // transform feedback returns gl_Position of every vertex in mesh order.
  g.BindTransformFeedback(GL_TRANSFORM_FEEDBACK, cx().feedback_object);
  g.BindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, buffer);
  g.BufferData(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLsizeiptr>(n) * 16, nullptr, GL_STREAM_READ);
  const GLboolean discard = g.IsEnabled(GL_RASTERIZER_DISCARD);
  if (!discard) g.Enable(GL_RASTERIZER_DISCARD);
  g.BeginTransformFeedback(GL_POINTS);
  // The draw's first instance (one instance: split instanced draws are recorded one by one).
  if (call.base_instance != 0)
    g.DrawArraysInstancedBaseInstance(GL_POINTS, static_cast<GLint>(cx().last_mesh_first), static_cast<GLsizei>(n),
                                      1, call.base_instance);
  else
    g.DrawArrays(GL_POINTS, static_cast<GLint>(cx().last_mesh_first), static_cast<GLsizei>(n));
  g.EndTransformFeedback();
  if (!discard) g.Disable(GL_RASTERIZER_DISCARD);
  g.BindTransformFeedback(GL_TRANSFORM_FEEDBACK, static_cast<GLuint>(prev_feedback));
  g.BindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLuint>(prev_buffer));
  cx().pending_deform.push_back(PendingDeform{static_cast<uint32_t>(cx().frame.draws.size() - 1), buffer, n});
}

void Interceptor::readDeformed() {
  if (cx().pending_deform.empty()) return;
  const RealGl& g = gl();
  GLint prev = 0;
  g.GetIntegerv(GL_COPY_READ_BUFFER_BINDING, &prev);
  for (const PendingDeform& d : cx().pending_deform) {
    std::vector<float>& out = cx().frame.draws[d.draw_index].deformed_clip_xyzw;
    out.resize(static_cast<size_t>(d.vertices) * 4);
    g.BindBuffer(GL_COPY_READ_BUFFER, d.buffer);
    g.GetBufferSubData(GL_COPY_READ_BUFFER, 0, static_cast<GLsizeiptr>(out.size() * sizeof(float)), out.data());
  }
  g.BindBuffer(GL_COPY_READ_BUFFER, static_cast<GLuint>(prev));
  cx().pending_deform.clear();
}

}  // namespace capture
}  // namespace viper
