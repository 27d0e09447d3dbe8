// Shaders, programs, buffers and textures: rewriting, content keys and shadow copies.
#include "interceptor.h"
#include "pixel_transfer.h"

#include "viper/capture/content_key.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace viper {
namespace capture {

namespace {

GLenum bindingOf(GLenum target) {
  switch (target) {
    case GL_ARRAY_BUFFER: return GL_ARRAY_BUFFER_BINDING;
    case GL_ELEMENT_ARRAY_BUFFER: return GL_ELEMENT_ARRAY_BUFFER_BINDING;
    case GL_COPY_READ_BUFFER: return GL_COPY_READ_BUFFER_BINDING;
    case GL_COPY_WRITE_BUFFER: return GL_COPY_WRITE_BUFFER_BINDING;
    case GL_TRANSFORM_FEEDBACK_BUFFER: return GL_TRANSFORM_FEEDBACK_BUFFER_BINDING;
    case GL_SHADER_STORAGE_BUFFER: return GL_SHADER_STORAGE_BUFFER_BINDING;
    case GL_UNIFORM_BUFFER: return GL_UNIFORM_BUFFER_BINDING;          // matrices in uniform blocks
    case GL_DRAW_INDIRECT_BUFFER: return GL_DRAW_INDIRECT_BUFFER_BINDING;
    // A buffer object has no type: the target it is made or filled on says nothing of how it is
    // drawn from later (wined3d makes its vertex and index buffers on GL_PIXEL_UNPACK_BUFFER and
    // fills them on the array targets), so buffers are shadowed whatever the target.
    case GL_PIXEL_PACK_BUFFER: return GL_PIXEL_PACK_BUFFER_BINDING;
    case GL_PIXEL_UNPACK_BUFFER: return GL_PIXEL_UNPACK_BUFFER_BINDING;
    case GL_TEXTURE_BUFFER: return GL_TEXTURE_BUFFER_BINDING;
    case GL_ATOMIC_COUNTER_BUFFER: return GL_ATOMIC_COUNTER_BUFFER_BINDING;
    case GL_DISPATCH_INDIRECT_BUFFER: return GL_DISPATCH_INDIRECT_BUFFER_BINDING;
    case GL_QUERY_BUFFER: return GL_QUERY_BUFFER_BINDING;
    default: return 0;
  }
}

GLenum samplerTarget(GLenum type) {
  switch (type) {
    case GL_SAMPLER_2D: case GL_SAMPLER_2D_SHADOW: case GL_INT_SAMPLER_2D: case GL_UNSIGNED_INT_SAMPLER_2D:
      return GL_TEXTURE_2D;
    case GL_SAMPLER_CUBE: case GL_SAMPLER_CUBE_SHADOW: return GL_TEXTURE_CUBE_MAP;
    case GL_SAMPLER_3D: return GL_TEXTURE_3D;
    case GL_SAMPLER_2D_ARRAY: case GL_SAMPLER_2D_ARRAY_SHADOW: return GL_TEXTURE_2D_ARRAY;
    default: return 0;
  }
}

// What the GL says of the active uniform `name` of `program` (index GL_INVALID_INDEX: none such).
struct ActiveUniform {
  GLuint index = GL_INVALID_INDEX;
  GLint block = -1, offset = -1, matrix_stride = 0, array_stride = 0, size = 0, row_major = 0, type = 0;
};

ActiveUniform activeUniform(GLuint program, const std::string& name) {
  const RealGl& g = gl();
  ActiveUniform u;
  const GLchar* names[1] = {name.c_str()};
  g.GetUniformIndices(program, 1, names, &u.index);
  if (u.index == GL_INVALID_INDEX) return u;
  const std::pair<GLenum, GLint*> properties[] = {
      {GL_UNIFORM_BLOCK_INDEX, &u.block},         {GL_UNIFORM_OFFSET, &u.offset},
      {GL_UNIFORM_MATRIX_STRIDE, &u.matrix_stride}, {GL_UNIFORM_ARRAY_STRIDE, &u.array_stride},
      {GL_UNIFORM_SIZE, &u.size},                 {GL_UNIFORM_IS_ROW_MAJOR, &u.row_major},
      {GL_UNIFORM_TYPE, &u.type}};
  for (const auto& [pname, value] : properties) g.GetActiveUniformsiv(program, 1, &u.index, pname, value);
  return u;
}

// Four vec4 elements of an array the profile names (`vs_cb0[4] rows`): of a default-block uniform
// array, or of an array member of a uniform block.
MatrixSource elementsSource(GLuint program, const MatrixName& matrix) {
  MatrixSource m;
  m.row_major = matrix.rows;
  const ActiveUniform u = activeUniform(program, matrix.name + "[0]");
  // The four elements must be active ones of a vec4 array (a driver may trim an array to the
  // elements the shader reads).
  if (u.index == GL_INVALID_INDEX || u.type != GL_FLOAT_VEC4 || matrix.first_element + 4 > u.size) return m;
  if (u.block < 0) {
    for (int k = 0; k < 4; ++k) {
      const std::string element = matrix.name + "[" + std::to_string(matrix.first_element + k) + "]";
      m.element_locations[k] = gl().GetUniformLocation(program, element.c_str());
      if (m.element_locations[k] < 0) return MatrixSource{};
    }
    return m;
  }
  if (u.offset < 0 || u.array_stride <= 0) return m;
  m.block = static_cast<GLuint>(u.block);
  m.offset = u.offset + matrix.first_element * u.array_stride;
  m.matrix_stride = u.array_stride;
  return m;
}

// A matrix the profile names: a default-block uniform, or a member of a uniform block.
MatrixSource matrixSource(GLuint program, const std::string& text) {
  MatrixSource m;
  if (text.empty()) return m;
  MatrixName matrix;
  try {
    matrix = parseMatrixName(text);  // the profile's parser checked it
  } catch (const std::invalid_argument&) {
    return m;
  }
  if (matrix.isElements()) return elementsSource(program, matrix);
  m.location = gl().GetUniformLocation(program, matrix.name.c_str());
  if (m.location >= 0) return m;
  const ActiveUniform u = activeUniform(program, matrix.name);
  if (u.index == GL_INVALID_INDEX || u.block < 0 || u.offset < 0 || u.type != GL_FLOAT_MAT4) return m;
  m.block = static_cast<GLuint>(u.block);
  m.offset = u.offset;
  m.matrix_stride = u.matrix_stride > 0 ? u.matrix_stride : 16;
  m.row_major = u.row_major != 0;
  return m;
}

}  // namespace

namespace {
std::string glEnumName(GLenum e) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%04x", static_cast<unsigned>(e));
  return text;
}
}  // namespace

void Interceptor::logOnce(const std::string& message) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!logged_.insert(message).second) return;
  }
  std::fprintf(stderr, "[viper capture] %s\n", message.c_str());
}

void Interceptor::programBinary(GLuint program) {
  // Not passed on: the program stays unlinked, reads GL_LINK_STATUS false, and builds from source.
  logOnce("glProgramBinary refused (program " + std::to_string(program) +
          "): programs are linked from source so that the capture layer can rewrite their shaders");
}

void Interceptor::shaderSource(GLuint shader, GLsizei count, const GLchar* const* strings, const GLint* lengths) {
  const RealGl& g = gl();
  // A call the GL refuses (no such shader, a negative count) is passed on untouched before the
  // layer reads anything: programs test those errors with pointers that are not strings.
  if (count <= 0 || !strings || !g.IsShader(shader)) return g.ShaderSource(shader, count, strings, lengths);
  ShaderInfo info;
  for (GLsizei i = 0; i < count; ++i) {
    if (!strings[i]) continue;
    info.original += (lengths && lengths[i] >= 0) ? std::string(strings[i], lengths[i]) : std::string(strings[i]);
  }
  GLint type = 0;
  g.GetShaderiv(shader, GL_SHADER_TYPE, &type);
  info.type = static_cast<GLenum>(type);
  if (info.type == GL_FRAGMENT_SHADER) {
    info.rewrite = rewriteFragmentShader(info.original);
    if (!info.rewrite.ok) {
      char key[32];
      std::snprintf(key, sizeof(key), "%016llx", static_cast<unsigned long long>(contentKey(info.original)));
      logOnce("fragment shader " + std::string(key) + " not rewritten, its draws get no ids: " + info.rewrite.reason);
    }
  }
  if (info.rewrite.ok) {
    const GLchar* src = info.rewrite.source.c_str();
    g.ShaderSource(shader, 1, &src, nullptr);
  } else {
    g.ShaderSource(shader, count, strings, lengths);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  shaders_[shader] = std::move(info);
}

void Interceptor::compileShader(GLuint shader) {
  const RealGl& g = gl();
  g.CompileShader(shader);
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = shaders_.find(shader);
  if (it == shaders_.end() || !it->second.rewrite.ok) return;
  GLint ok = 0;
  g.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok) return;
  // Our rewrite broke a shader that may well compile as written: give the program its own.
  char log[512] = "";
  g.GetShaderInfoLog(shader, sizeof(log), nullptr, log);
  std::string first_line(log);
  first_line = first_line.substr(0, first_line.find('\n'));
  std::fprintf(stderr, "[viper capture] rewritten fragment shader %u did not compile (%s); no ids for it\n", shader,
               first_line.c_str());
  it->second.rewrite.ok = false;
  const GLchar* src = it->second.original.c_str();
  g.ShaderSource(shader, 1, &src, nullptr);
  g.CompileShader(shader);
}

bool Interceptor::hiddenUniforms(GLuint program, std::vector<GLuint>& hidden, GLint& visible_max_length) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = programs_.find(program);
  if (it == programs_.end() || it->second.hidden_uniforms.empty()) return false;
  hidden = it->second.hidden_uniforms;
  visible_max_length = it->second.visible_uniform_max_length;
  return true;
}

void Interceptor::programParameter(GLuint program, GLenum pname, GLint value) {
  if (pname != GL_PROGRAM_SEPARABLE) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (value) separable_programs_.insert(program);
  else separable_programs_.erase(program);
}

void Interceptor::transformFeedbackVaryings(GLuint program) {
  std::lock_guard<std::mutex> lock(mutex_);
  programs_with_own_feedback_.insert(program);
}

void Interceptor::linkProgram(GLuint program) {
  const RealGl& g = gl();
  GLuint attached[16];
  GLsizei n = 0;
  g.GetAttachedShaders(program, 16, &n, attached);
  ProgramInfo info;
  std::string stage_sources[6], vertex_source;
  const ShaderInfo* fragment = nullptr;
  GLuint fragment_name = 0;
  int fragment_count = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (GLsizei i = 0; i < n; ++i) {
      auto it = shaders_.find(attached[i]);
      if (it == shaders_.end()) continue;
      const ShaderInfo& s = it->second;
      int stage = 5;
      switch (s.type) {
        case GL_VERTEX_SHADER: stage = 0; vertex_source += s.original; break;
        case GL_TESS_CONTROL_SHADER: stage = 1; info.has_geometry_stage = true; break;
        case GL_TESS_EVALUATION_SHADER: stage = 2; info.has_geometry_stage = true; break;
        case GL_GEOMETRY_SHADER: stage = 3; info.has_geometry_stage = true; break;
        case GL_FRAGMENT_SHADER: stage = 4; fragment = &s; fragment_name = attached[i]; ++fragment_count; break;
        default: break;
      }
      stage_sources[stage] += s.original;
    }
    info.own_feedback = programs_with_own_feedback_.count(program) > 0;
  }
  std::string all;
  for (const std::string& s : stage_sources) all += s;
  info.key = contentKey(all);
  const ProgramProfile& profile = *profile_.match(vertex_source, info.key);

  info.rewritten = fragment_count == 1 && fragment->rewrite.ok;
  if (info.rewritten && !fragment->rewrite.legacy) {
    g.BindFragDataLocation(program, kIdOutputLocation, kIdOutputName);
    if (!fragment->rewrite.explicit_location) g.BindFragDataLocation(program, 0, fragment->rewrite.color_output.c_str());
  }
  // Overlay programs keep their rewritten shader (its id output goes to no buffer) but write no ids.
  info.overlay = profile.overlay;
  if (info.overlay) info.rewritten = false;
  const std::string code = stripGlslComments(all);
  info.reads_draw_parameters = code.find("gl_InstanceID") != std::string::npos ||
                               code.find("gl_BaseInstance") != std::string::npos ||
                               code.find("gl_DrawID") != std::string::npos;
  info.deforming = profile.deforming == Deforming::kYes ||
                   (profile.deforming == Deforming::kAuto && declaresMat4ArrayUniform(vertex_source));
  if (info.own_feedback || info.has_geometry_stage) info.deforming = false;
  static const char* const kVaryings[1] = {"gl_Position"};
  if (info.deforming) g.TransformFeedbackVaryings(program, 1, kVaryings, GL_INTERLEAVED_ATTRIBS);
  // A geometry or tessellation stage that does not write gl_PrimitiveID leaves the fragment
  // shader's undefined (and llvmpipe draws nothing when it is read): this program links with a
  // fragment shader that writes primitive id 0, and the shader object gets its source back after.
  const std::string& last_stage = stage_sources[3].empty() ? stage_sources[2] : stage_sources[3];
  // A separable program without a vertex stage is used in a pipeline with stages of other
  // programs, which its link cannot see: primitive id 0 too. (Separable as glProgramParameteri
  // made it: glGetProgramiv answers GL_PROGRAM_SEPARABLE only once the program is linked.)
  bool separable = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    separable = separable_programs_.count(program) > 0;
  }
  const bool unknown_stages = separable && stage_sources[0].empty();
  std::string restore_source;
  if (info.rewritten && (unknown_stages || (info.has_geometry_stage && last_stage.find("gl_PrimitiveID") == std::string::npos))) {
    const FragmentRewrite without = rewriteFragmentShader(fragment->original, /*primitive_ids=*/false);
    if (without.ok) {
      restore_source = fragment->rewrite.source;
      const GLchar* src = without.source.c_str();
      g.ShaderSource(fragment_name, 1, &src, nullptr);
      g.CompileShader(fragment_name);
    }
  }
  g.LinkProgram(program);
  if (!restore_source.empty()) {
    const GLchar* src = restore_source.c_str();
    g.ShaderSource(fragment_name, 1, &src, nullptr);
    g.CompileShader(fragment_name);
  }
  GLint linked = 0;
  g.GetProgramiv(program, GL_LINK_STATUS, &linked);
  if (!linked && info.deforming) {
    g.TransformFeedbackVaryings(program, 0, nullptr, GL_INTERLEAVED_ATTRIBS);
    g.LinkProgram(program);
    g.GetProgramiv(program, GL_LINK_STATUS, &linked);
    info.deforming = false;
  }
  if (linked) {
    if (info.rewritten) {
      info.loc_draw_id = g.GetUniformLocation(program, kDrawIdUniform);
      info.loc_alpha_test = g.GetUniformLocation(program, kAlphaTestUniform);
    }
    info.world = matrixSource(program, profile.world);
    info.view = matrixSource(program, profile.view);
    info.projection = matrixSource(program, profile.projection);
    info.model_view = matrixSource(program, profile.model_view);
    info.view_projection = matrixSource(program, profile.view_projection);
    info.model_view_projection = matrixSource(program, profile.model_view_projection);
    info.world_space = profile.world_space;
    info.combined = profile.world_space || !profile.model_view.empty() || !profile.view_projection.empty() ||
                    !profile.model_view_projection.empty();
    info.matrix_stack = !profile.matrix_stack.empty();
    info.stack_push_world = profile.matrix_stack == "push_world";
    if (info.matrix_stack || info.combined || !profile.world.empty() || profile.hasInstanceTransform())
      info.expected_matrices |= kHasWorld;
    if (info.matrix_stack || info.combined || !profile.view.empty()) info.expected_matrices |= kHasView;
    if (info.matrix_stack || info.combined || !profile.projection.empty()) info.expected_matrices |= kHasProjection;
    info.vertex_array_position = profile.position == "gl_Vertex";
    info.position_attrib = profile.position.empty()       ? 0
                           : info.vertex_array_position ? -1
                                                        : g.GetAttribLocation(program, profile.position.c_str());
    auto attribute = [&](const std::string& name) {
      return name.empty() ? -1 : g.GetAttribLocation(program, name.c_str());
    };
    info.instance.world = attribute(profile.instance_world);
    info.instance.translation = attribute(profile.instance_translation);
    info.instance.rotation = attribute(profile.instance_rotation);
    info.instance.scale = attribute(profile.instance_scale);
    info.instance.rotation_conjugate = profile.instance_rotation_conjugate;
    for (const std::string* name : {&profile.world, &profile.view, &profile.projection, &profile.model_view,
                                    &profile.view_projection, &profile.model_view_projection, &profile.instance_world,
                                    &profile.instance_translation, &profile.instance_rotation, &profile.instance_scale}) {
      if (name->empty()) continue;
      const bool found = (name == &profile.world && info.world.found()) ||
                         (name == &profile.view && info.view.found()) ||
                         (name == &profile.projection && info.projection.found()) ||
                         (name == &profile.model_view && info.model_view.found()) ||
                         (name == &profile.view_projection && info.view_projection.found()) ||
                         (name == &profile.model_view_projection && info.model_view_projection.found()) ||
                         (name == &profile.instance_world && info.instance.world >= 0) ||
                         (name == &profile.instance_translation && info.instance.translation >= 0) ||
                         (name == &profile.instance_rotation && info.instance.rotation >= 0) ||
                         (name == &profile.instance_scale && info.instance.scale >= 0);
      if (!found) {
        char key[32];
        std::snprintf(key, sizeof(key), "%016llx", static_cast<unsigned long long>(info.key));
        logOnce("program " + std::string(key) + ": the profile names '" + *name +
                "', which it does not use (no matrix recorded from it)");
      }
    }
    GLint uniforms = 0, max_length = 0;
    g.GetProgramiv(program, GL_ACTIVE_UNIFORMS, &uniforms);
    g.GetProgramiv(program, GL_ACTIVE_UNIFORM_MAX_LENGTH, &max_length);
    std::vector<char> name_buffer(static_cast<size_t>(std::max<GLint>(max_length, 1)) + 1);
    for (GLint i = 0; i < uniforms; ++i) {
      char* name = name_buffer.data();
      GLint size = 0;
      GLenum type = 0;
      GLsizei length = 0;
      g.GetActiveUniform(program, static_cast<GLuint>(i), static_cast<GLsizei>(name_buffer.size()), &length, &size,
                         &type, name);
      if (std::strcmp(name, kDrawIdUniform) == 0 || std::strcmp(name, kAlphaTestUniform) == 0) {
        info.hidden_uniforms.push_back(static_cast<GLuint>(i));
        continue;
      }
      info.visible_uniform_max_length = std::max<GLint>(info.visible_uniform_max_length, length + 1);
      const GLenum target = samplerTarget(type);
      if (!target) continue;
      info.sampler_locations.push_back(g.GetUniformLocation(program, name));
      info.sampler_targets.push_back(target);
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  programs_[program] = std::move(info);
  if (program == cx().current_program) cx().current_program_info = nullptr;
}

void Interceptor::useProgram(GLuint program) {
  cx().current_program = program;
  cx().current_program_info = nullptr;
}

ProgramInfo* Interceptor::currentProgram() {
  if (!cx().current_program_info && cx().current_program) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = programs_.find(cx().current_program);
    if (it != programs_.end()) cx().current_program_info = &it->second;
  }
  return cx().current_program_info;
}

GLuint Interceptor::boundBuffer(GLenum target) {
  const GLenum binding = bindingOf(target);
  if (!binding) return 0;
  GLint name = 0;
  gl().GetIntegerv(binding, &name);
  return static_cast<GLuint>(name);
}

void Interceptor::bufferData(GLenum target, GLuint name, GLsizeiptr size, const void* data) {
  if (!name) name = boundBuffer(target);
  if (!name || size < 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  BufferShadow& b = buffers_[name];
  const uint8_t* p = static_cast<const uint8_t*>(data);
  if (p) b.data.assign(p, p + size);
  else b.data.assign(static_cast<size_t>(size), 0);
  ++b.version;
}

void Interceptor::bufferStorage(GLenum target, GLuint name, GLsizeiptr size, const void* data) {
  bufferData(target, name, size, data);  // immutable storage: its contents as glBufferData's
}

bool Interceptor::readBufferBytes(GLuint name, size_t offset, size_t size, void* out) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = buffers_.find(name);
  if (it == buffers_.end()) return false;
  const BufferShadow& b = it->second;
  if (b.map_pointer && b.map_persistent && offset >= b.map_offset && offset + size <= b.map_offset + b.map_length) {
    std::memcpy(out, static_cast<const uint8_t*>(b.map_pointer) + (offset - b.map_offset), size);
    return true;
  }
  if (offset + size > b.data.size()) return false;
  std::memcpy(out, b.data.data() + offset, size);
  return true;
}

void Interceptor::bufferSubData(GLenum target, GLuint name, GLintptr offset, GLsizeiptr size, const void* data) {
  if (!name) name = boundBuffer(target);
  if (!name || !data || offset < 0 || size < 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = buffers_.find(name);
  if (it == buffers_.end() || static_cast<size_t>(offset + size) > it->second.data.size()) return;
  std::memcpy(it->second.data.data() + offset, data, static_cast<size_t>(size));
  ++it->second.version;
}

void Interceptor::mapped(GLenum target, void* pointer, GLintptr offset, GLsizeiptr length, GLbitfield access) {
  const GLuint name = boundBuffer(target);
  if (!name || !pointer || !(access & GL_MAP_WRITE_BIT)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = buffers_.find(name);
  if (it == buffers_.end()) return;
  it->second.map_pointer = pointer;
  it->second.map_offset = static_cast<size_t>(offset);
  it->second.map_length = length < 0 ? it->second.data.size() - offset : static_cast<size_t>(length);
  it->second.map_persistent = (access & GL_MAP_PERSISTENT_BIT) != 0;
}

void Interceptor::beforeUnmap(GLenum target) {
  const GLuint name = boundBuffer(target);
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = buffers_.find(name);
  if (it == buffers_.end() || !it->second.map_pointer) return;
  BufferShadow& b = it->second;
  if (b.map_offset + b.map_length <= b.data.size())
    std::memcpy(b.data.data() + b.map_offset, b.map_pointer, b.map_length);
  b.map_pointer = nullptr;
  b.map_persistent = false;
  ++b.version;
}

void Interceptor::copyBufferSubData(GLenum read_target, GLenum write_target, GLintptr read_offset,
                                   GLintptr write_offset, GLsizeiptr size) {
  const GLuint src = boundBuffer(read_target), dst = boundBuffer(write_target);
  std::lock_guard<std::mutex> lock(mutex_);
  auto s = buffers_.find(src), d = buffers_.find(dst);
  if (s == buffers_.end() || d == buffers_.end() || size < 0) return;
  if (static_cast<size_t>(read_offset + size) > s->second.data.size() ||
      static_cast<size_t>(write_offset + size) > d->second.data.size())
    return;
  std::memmove(d->second.data.data() + write_offset, s->second.data.data() + read_offset, static_cast<size_t>(size));
  ++d->second.version;
}

void Interceptor::deleteBuffers(GLsizei n, const GLuint* names) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (GLsizei i = 0; i < n; ++i) buffers_.erase(names[i]);
}

uint64_t Interceptor::bufferKey(GLuint name) {
  auto it = buffers_.find(name);
  if (it == buffers_.end()) return 0;
  BufferShadow& b = it->second;
  if (b.key_version != b.version) {
    b.key = contentKey(b.data.data(), b.data.size());
    b.key_version = b.version;
  }
  return b.key;
}

void Interceptor::bindTexture(GLenum target, GLuint name) {
  cx().unit_bindings[(static_cast<uint64_t>(cx().active_unit) << 32) | target] = name;
}

void Interceptor::texImage(GLenum target, GLint level, GLsizei w, GLsizei h, GLenum format, GLenum type,
                           const void* pixels, bool sub, GLint x, GLint y) {
  const int32_t params[6] = {static_cast<int32_t>(format), static_cast<int32_t>(type), x, y, w, h};
  uint64_t key = contentKey(params, sizeof(params));
  if (pixels && !glInt(GL_PIXEL_UNPACK_BUFFER_BINDING) && w > 0 && h > 0) {
    // Exactly the bytes the GL reads (pixel_transfer.h); none for a format it does not know.
    UnpackState unpack;
    unpack.row_length = glInt(GL_UNPACK_ROW_LENGTH);
    unpack.skip_pixels = glInt(GL_UNPACK_SKIP_PIXELS);
    unpack.skip_rows = glInt(GL_UNPACK_SKIP_ROWS);
    unpack.alignment = glInt(GL_UNPACK_ALIGNMENT);
    UnpackedSpan span;
    if (unpackedSpan(format, type, w, h, unpack, span))
      key = combineKeys(key, contentKey(static_cast<const uint8_t*>(pixels) + span.offset, span.bytes));
    else
      logOnce("texture upload of format " + glEnumName(format) + ", type " + glEnumName(type) +
              ": not a pixel transfer the layer knows; its textures are keyed by size only");
  }
  storeTextureKey(target, level, sub, key);
}

void Interceptor::compressedTexImage(GLenum target, GLint level, GLsizei w, GLsizei h, GLenum format, GLsizei bytes,
                                     const void* data, bool sub, GLint x, GLint y) {
  const int32_t params[6] = {static_cast<int32_t>(format), -1, x, y, w, h};
  uint64_t key = contentKey(params, sizeof(params));
  if (data && bytes > 0 && !glInt(GL_PIXEL_UNPACK_BUFFER_BINDING))
    key = combineKeys(key, contentKey(data, static_cast<size_t>(bytes)));
  storeTextureKey(target, level, sub, key);
}

void Interceptor::storeTextureKey(GLenum target, GLint level, bool sub, uint64_t key) {
  if (target >= GL_TEXTURE_CUBE_MAP_POSITIVE_X && target <= GL_TEXTURE_CUBE_MAP_NEGATIVE_Z)
    target = GL_TEXTURE_CUBE_MAP;
  auto bound = cx().unit_bindings.find((static_cast<uint64_t>(cx().active_unit) << 32) | target);
  if (bound == cx().unit_bindings.end() || bound->second == 0) return;
  if (level > 0 && !sub) return;  // mip levels follow from level 0
  std::lock_guard<std::mutex> lock(mutex_);
  uint64_t& stored = texture_keys_[bound->second];
  stored = sub ? combineKeys(stored, key) : key;
}

void Interceptor::deleteTextures(GLsizei n, const GLuint* names) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (GLsizei i = 0; i < n; ++i) texture_keys_.erase(names[i]);
}

uint64_t Interceptor::textureKey(GLenum target, GLuint unit) {
  auto bound = cx().unit_bindings.find((static_cast<uint64_t>(unit) << 32) | target);
  if (bound == cx().unit_bindings.end()) return 0;
  // Under the lock: a loader thread may be uploading (storeTextureKey inserts, which may rehash).
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = texture_keys_.find(bound->second);
  return it == texture_keys_.end() ? 0 : it->second;
}

}  // namespace capture
}  // namespace viper
