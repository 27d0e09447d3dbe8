// Procedural meshes of the test scene, built on the CPU in the vertex layouts the shaders read.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace viper {
namespace scene {

/// Vertex layout of a mesh (all attributes float, interleaved).
enum class VertexLayout {
  kLit,      ///< aPos(3) aNormal(3)
  kSkinned,  ///< aPos(3) aNormal(3) aBoneIds(4) aWeights(4)
  kRain,     ///< aPos(3) aAlpha(1)
};

/// Floats per vertex of a layout.
int floatsPerVertex(VertexLayout layout);

/// One mesh: interleaved vertices and a triangle list, in the mesh's own (model) coordinates.
struct MeshData {
  std::string name;
  VertexLayout layout = VertexLayout::kLit;
  std::vector<float> vertices;
  std::vector<uint32_t> indices;
};

/// Flat grid in the plane z = `z`, centred on the origin, `cells` x `cells` quads, normal +Z.
MeshData makeGrid(const std::string& name, float half_x, float half_y, float z, int cells);
/// Axis-aligned box with flat-shaded faces.
MeshData makeBox(const std::string& name, const Eigen::Vector3f& center, const Eigen::Vector3f& size);
/// Closed cylinder whose axis is the model Y axis (a wheel on a car driving along X).
MeshData makeWheel(const std::string& name, const Eigen::Vector3f& center, float radius, float width, int sides);
/// Vertical tube from z = 0 to z = `height` made of `bones` equal segments, each weighted to its bone
/// and blended linearly with the neighbour within `blend` metres of a joint.
MeshData makeSkinnedTube(const std::string& name, float radius, float height, int bones, float blend, int sides,
                         int rings);
/// `count` thin vertical quads spread over a box (seeded), facing along `normal`; alpha runs
/// 0.05 (top) -> 0.6 (middle) -> 0.05 (bottom) along each streak.
MeshData makeRainStreaks(const std::string& name, uint64_t seed, int count, const Eigen::Vector3f& box_min,
                         const Eigen::Vector3f& box_max, const Eigen::Vector3f& normal);

}  // namespace scene
}  // namespace viper
