#include "renderer.h"

#include "shaders.h"

#include "gl_common/shader_build.h"

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace viper {
namespace scene {

Renderer::Renderer(const GlApi& gl, const std::vector<MeshData>& meshes, uint32_t width, uint32_t height)
    : gl_(gl), width_(width), height_(height) {
  programs_[static_cast<int>(ProgramKind::kLit)] = buildProgram(kLitVertexShader, kLitFragmentShader, "lit");
  programs_[static_cast<int>(ProgramKind::kSkinned)] =
      buildProgram(kSkinnedVertexShader, kLitFragmentShader, "skinned");
  programs_[static_cast<int>(ProgramKind::kRain)] = buildProgram(kRainVertexShader, kRainFragmentShader, "rain");

  for (const MeshData& m : meshes) {
    GpuMesh g;
    gl_.GenVertexArrays(1, &g.vao);
    gl_.BindVertexArray(g.vao);
    gl_.GenBuffers(1, &g.vbo);
    gl_.BindBuffer(GL_ARRAY_BUFFER, g.vbo);
    gl_.BufferData(GL_ARRAY_BUFFER, m.vertices.size() * sizeof(float), m.vertices.data(), GL_STATIC_DRAW);
    gl_.GenBuffers(1, &g.ibo);
    gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ibo);
    gl_.BufferData(GL_ELEMENT_ARRAY_BUFFER, m.indices.size() * sizeof(uint32_t), m.indices.data(), GL_STATIC_DRAW);
    // Interleaved attributes: positions are never tightly packed, as in most real programs.
    const GLsizei stride = floatsPerVertex(m.layout) * sizeof(float);
    auto attribute = [&](GLuint location, GLint size, int offset_floats) {
      gl_.EnableVertexAttribArray(location);
      gl_.VertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, stride,
                              reinterpret_cast<const void*>(offset_floats * sizeof(float)));
    };
    attribute(0, 3, 0);
    if (m.layout == VertexLayout::kRain) {
      attribute(1, 1, 3);
    } else {
      attribute(1, 3, 3);
      if (m.layout == VertexLayout::kSkinned) {
        attribute(2, 4, 6);
        attribute(3, 4, 10);
      }
    }
    g.index_count = static_cast<GLsizei>(m.indices.size());
    meshes_.push_back(g);
  }
  gl_.BindVertexArray(0);
  checkError("uploading meshes");
}

Renderer::~Renderer() {
  for (GpuMesh& g : meshes_) {
    gl_.DeleteVertexArrays(1, &g.vao);
    gl_.DeleteBuffers(1, &g.vbo);
    gl_.DeleteBuffers(1, &g.ibo);
  }
  for (Program& p : programs_) gl_.DeleteProgram(p.id);
}

Renderer::Program Renderer::buildProgram(const char* vertex_source, const char* fragment_source, const char* name) {
  Program p;
  const gl_common::ShaderCalls calls = gl_common::shaderCallsOf(gl_);
  const GLuint vs = gl_common::compileShader(calls, GL_VERTEX_SHADER, vertex_source, name);
  const GLuint fs = gl_common::compileShader(calls, GL_FRAGMENT_SHADER, fragment_source, name);
  p.id = gl_.CreateProgram();
  gl_.AttachShader(p.id, vs);
  gl_.AttachShader(p.id, fs);
  gl_common::linkProgram(calls, p.id, {vs, fs}, name);
  p.world = gl_.GetUniformLocation(p.id, "uWorld");
  p.view = gl_.GetUniformLocation(p.id, "uView");
  p.projection = gl_.GetUniformLocation(p.id, "uProj");
  p.color = gl_.GetUniformLocation(p.id, "uColor");
  p.bones = gl_.GetUniformLocation(p.id, "uBones");
  if (p.world < 0 || p.view < 0 || p.projection < 0)
    throw std::runtime_error(std::string("the ") + name + " program lacks uWorld, uView or uProj");
  return p;
}

void Renderer::checkError(const char* what) {
  const GLenum error = gl_.GetError();
  if (error != GL_NO_ERROR) {
    char buffer[128];
    std::snprintf(buffer, sizeof(buffer), "OpenGL error 0x%04x while %s", error, what);
    throw std::runtime_error(buffer);
  }
}

void Renderer::draw(const FrameState& frame) {
  gl_.Viewport(0, 0, static_cast<GLsizei>(width_), static_cast<GLsizei>(height_));
  gl_.ClearColor(0.53f, 0.70f, 0.90f, 1.0f);
  gl_.DepthMask(GL_TRUE);
  gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl_.Enable(GL_DEPTH_TEST);
  gl_.DepthFunc(GL_LESS);
  gl_.Disable(GL_CULL_FACE);
  gl_.Disable(GL_BLEND);

  // Like most programs, camera matrices are set once per program per frame, the world per draw.
  bool camera_set[3] = {false, false, false};
  const Program* current = nullptr;
  for (const DrawItem& item : frame.draws) {
    const int kind = static_cast<int>(item.program);
    const Program& p = programs_[kind];
    if (&p != current) {
      gl_.UseProgram(p.id);
      current = &p;
    }
    if (!camera_set[kind]) {
      gl_.UniformMatrix4fv(p.view, 1, GL_FALSE, frame.view.data());
      gl_.UniformMatrix4fv(p.projection, 1, GL_FALSE, frame.projection.data());
      camera_set[kind] = true;
    }
    if (item.program == ProgramKind::kRain) {
      // Transparent effect: blended over what is behind it, never written into the depth buffer.
      gl_.Enable(GL_BLEND);
      gl_.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      gl_.DepthMask(GL_FALSE);
    }
    gl_.UniformMatrix4fv(p.world, 1, GL_FALSE, item.world.data());
    if (p.color >= 0) gl_.Uniform3f(p.color, item.color.x(), item.color.y(), item.color.z());
    if (item.program == ProgramKind::kSkinned)
      gl_.UniformMatrix4fv(p.bones, static_cast<GLsizei>(item.bones.size()), GL_FALSE, item.bones.front().data());
    const GpuMesh& g = meshes_.at(item.mesh);
    gl_.BindVertexArray(g.vao);
    gl_.DrawElements(GL_TRIANGLES, g.index_count, GL_UNSIGNED_INT, nullptr);
    if (item.program == ProgramKind::kRain) {
      gl_.Disable(GL_BLEND);
      gl_.DepthMask(GL_TRUE);
    }
  }
  gl_.BindVertexArray(0);
  checkError("drawing the frame");
}

std::vector<uint8_t> Renderer::readColor() {
  const size_t row = static_cast<size_t>(width_) * 3;
  std::vector<uint8_t> bottom_up(row * height_);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl_.ReadPixels(0, 0, static_cast<GLsizei>(width_), static_cast<GLsizei>(height_), GL_RGB, GL_UNSIGNED_BYTE,
                 bottom_up.data());
  checkError("reading the frame back");
  std::vector<uint8_t> top_down(bottom_up.size());
  for (uint32_t y = 0; y < height_; ++y)
    std::memcpy(&top_down[y * row], &bottom_up[(height_ - 1 - y) * row], row);
  return top_down;
}

}  // namespace scene
}  // namespace viper

