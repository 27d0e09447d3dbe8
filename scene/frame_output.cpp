#include "frame_output.h"

#include <cstdio>
#include <filesystem>

namespace viper {
namespace scene {
namespace {

// The oracle record of a mesh: positions (floats 0..2 of each interleaved vertex, what aPos reads),
// indices and, for the skinned layout, bone ids and weights (floats 6..9 and 10..13).
OracleMesh toOracleMesh(const MeshData& m) {
  OracleMesh o;
  o.name = m.name;
  o.indices = m.indices;
  const size_t stride = static_cast<size_t>(floatsPerVertex(m.layout));
  for (size_t v = 0; v + stride <= m.vertices.size(); v += stride) {
    o.positions_xyz.insert(o.positions_xyz.end(), m.vertices.begin() + v, m.vertices.begin() + v + 3);
    if (m.layout != VertexLayout::kSkinned) continue;
    for (size_t k = 6; k < 10; ++k) o.bone_ids.push_back(static_cast<uint32_t>(m.vertices[v + k]));
    o.bone_weights.insert(o.bone_weights.end(), m.vertices.begin() + v + 10, m.vertices.begin() + v + 14);
  }
  return o;
}

OracleFrame toOracle(uint64_t number, const FrameState& s, const World& world) {
  OracleFrame f;
  f.number = number;
  f.time_s = s.time_s;
  f.view = s.view;
  f.projection = s.projection;
  f.map_from_camera_body = s.map_from_camera_body;
  for (size_t i = 0; i < s.draws.size(); ++i) {
    const DrawItem& item = s.draws[i];
    OracleDraw d;
    d.index = static_cast<uint32_t>(i);
    d.object_id = item.object_id;
    d.class_id = item.class_id;
    d.part = item.part;
    d.mesh = world.meshes()[item.mesh].name;
    d.world = item.world;
    d.skinned = item.program == ProgramKind::kSkinned;
    d.bones = item.bones;
    f.draws.push_back(std::move(d));
  }
  return f;
}

}  // namespace

void writeOracleFrame(OracleWriter& oracle, uint64_t number, const FrameState& state, const World& world) {
  for (const DrawItem& item : state.draws)
    if (!oracle.hasMesh(world.meshes()[item.mesh].name)) oracle.writeMesh(toOracleMesh(world.meshes()[item.mesh]));
  oracle.write(toOracle(number, state, world));
}

std::string dumpPath(const std::string& dir, uint64_t number) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06llu.ppm", static_cast<unsigned long long>(number));
  return (std::filesystem::path(dir) / name).string();
}

}  // namespace scene
}  // namespace viper
