// Draws the scene's frames into the default framebuffer of the current context.
#pragma once

#include "gl_api.h"
#include "world.h"

#include <cstdint>
#include <vector>

namespace viper {
namespace scene {

/// Owns the GL objects (one VAO/VBO/IBO per mesh, three programs) and issues one draw call per
/// DrawItem, in order.
class Renderer {
 public:
  /// Compiles the programs and uploads `meshes`. Throws std::runtime_error with the compile/link log
  /// or the GL error on failure.
  Renderer(const GlApi& gl, const std::vector<MeshData>& meshes, uint32_t width, uint32_t height);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Clears to the sky colour and draws `frame`'s items. Throws std::runtime_error on a GL error.
  void draw(const FrameState& frame);

  /// Reads framebuffer 0 back as rgb8, top row first (width * height * 3 bytes).
  std::vector<uint8_t> readColor();

 private:
  struct Program {
    GLuint id = 0;
    GLint world = -1, view = -1, projection = -1, color = -1, bones = -1;
  };
  struct GpuMesh {
    GLuint vao = 0, vbo = 0, ibo = 0;
    GLsizei index_count = 0;
  };

  Program buildProgram(const char* vertex_source, const char* fragment_source, const char* name);
  void checkError(const char* what);

  const GlApi& gl_;
  uint32_t width_, height_;
  Program programs_[3];
  std::vector<GpuMesh> meshes_;
};

}  // namespace scene
}  // namespace viper
