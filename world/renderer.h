// OpenGL renderer of the world: uploads the mesh library (one vertex/index buffer set per mesh),
// one procedural texture per class, and issues one draw call per object part with that object's
// world matrix. Optionally records every draw for the oracle file.
#pragma once

#include "conditions.h"
#include "mesh_library.h"
#include "shaders.h"

#include "viper/ground_truth/oracle.h"

#include <array>
#include <cstdint>
#include <vector>

namespace viper {
namespace world {

/// One draw of one object part.
struct DrawRequest {
  uint32_t object_id = 0;
  uint8_t class_id = 0;
  const char* part = "body";
  int mesh = -1;
  Mat4 world;
  Vec3 tint{1, 1, 1};
  float emissive = 0;
  const std::vector<Mat4>* bones = nullptr;  ///< non-null: skinned program
};

/// Lighting of one frame.
struct FrameLighting {
  ConditionParams cond;
  Vec3 cam_pos;
  int light_count = 0;
  Vec3 light_pos[kMaxLights];
  Vec3 light_color[kMaxLights];
  Vec3 head_pos, head_dir;
  float head_on = 0;
};

/// Registers the sky dome, rain, snow and glare meshes (particle layout from `seed`).
void addEffectMeshes(MeshLibrary& meshes, uint32_t seed);

/// Issues the world's GL calls. Needs a current GL 3.3 core context for everything but the
/// constructor.
class Renderer {
 public:
  /// Uploads meshes (addEffectMeshes must have run), textures and programs. Throws
  /// std::runtime_error on GLSL errors.
  void init(const MeshLibrary& meshes, int width, int height);
  /// Records each following draw into `frame` (nullptr: no recording).
  void record(OracleFrame* frame) { record_ = frame; }
  /// Clears and sets the per-frame uniforms.
  void beginFrame(const Mat4& view, const Mat4& proj, const FrameLighting& lighting);
  /// Draws one object part (lit or skinned).
  void draw(const DrawRequest& request);
  /// Sky dome around the camera (after the opaque scene; it lies on the far plane).
  void drawSky(uint32_t object_id);
  /// Rain or snow particles around the camera at time t (alpha blended, no depth writes).
  void drawParticles(uint32_t object_id, double t);
  /// Sun glare sprite (sunset), additive.
  void drawGlare(uint32_t object_id);
  /// Reads the back buffer as tightly packed RGB rows, top row first.
  void readPixels(std::vector<uint8_t>& rgb) const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct GpuMesh {
    GLuint vao = 0;
    GLsizei index_count = 0;
  };
  struct Locations {
    GLint world = -1, view = -1, proj = -1, tint = -1, emissive = -1, road = -1, window = -1,
          tex_scale = -1, bones = -1, snow = -1;
  };
  void setFrameUniforms(GLuint program, const Mat4& view, const Mat4& proj, const FrameLighting& l);
  void recordDraw(uint32_t object_id, uint8_t class_id, const char* part, int mesh,
                  const Mat4& world, const std::vector<Mat4>* bones);

  const MeshLibrary* meshes_ = nullptr;
  std::vector<GpuMesh> gpu_;
  std::array<GLuint, 32> textures_{};
  std::array<GLuint, size_t(ProgramKind::kCount)> programs_{};
  std::array<Locations, size_t(ProgramKind::kCount)> loc_{};
  GLuint current_program_ = 0;
  int width_ = 0, height_ = 0;
  int sky_mesh_ = -1, rain_mesh_ = -1, snow_mesh_ = -1, glare_mesh_ = -1;
  Mat4 view_, proj_;
  FrameLighting lighting_;
  OracleFrame* record_ = nullptr;
};

}  // namespace world
}  // namespace viper
