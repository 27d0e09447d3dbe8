// Geometry of town furniture and scenery pieces, added into a MeshData at a pose. Object frames:
// x forward (the side facing the street or the viewer), y left, z up, origin on the ground.
#pragma once

#include "mesh_data.h"

#include <random>

namespace viper {
namespace world {

/// Street lamp: pole, arm reaching +x, lamp head at about 7 m.
void addStreetLamp(MeshData& m, const Mat4& at);
/// Tree: trunk and one to three crown blobs; size from `rng`.
void addTree(MeshData& m, const Mat4& at, std::mt19937& rng);
/// Bush or hedge piece (low vegetation), roughly `size` metres wide.
void addBush(MeshData& m, const Mat4& at, float size, std::mt19937& rng);
/// Fence from a to b (ground points): posts every 2 m and two rails.
void addFence(MeshData& m, Vec3 a, Vec3 b, float height);
/// Billboard on two posts, board facing +x.
void addBillboard(MeshData& m, const Mat4& at, Vec3 board_color);
/// Traffic sign: pole and a plate (round, triangular or square by `kind` 0..2) facing +x.
void addTrafficSign(MeshData& m, const Mat4& at, int kind);
/// Mobile barrier (striped construction barrier) along y.
void addBarrier(MeshData& m, const Mat4& at);
/// Trash: a bag or a few pieces of litter.
void addTrash(MeshData& m, const Mat4& at, std::mt19937& rng);
/// Building of footprint (depth along x, width along y) and height, with a roof, front at +x.
void addBuilding(MeshData& m, const Mat4& at, float depth, float width, float height, Vec3 color);

/// Stand-alone instance meshes (object space).
MeshData fireHydrantMesh();
MeshData chairMesh();
MeshData trashCanMesh();

}  // namespace world
}  // namespace viper
