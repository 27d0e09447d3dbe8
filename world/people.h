// Skinned people: a mesh bound to an 11-bone skeleton and the poses the world animates (walking,
// standing, sitting). Bone matrices map bind-pose object space to posed object space; the vertex
// shader blends them (uBones).
#pragma once

#include "mesh_library.h"

#include <vector>

namespace viper {
namespace world {

/// Number of bones of the person skeleton (the shader's uBones array has this size).
constexpr int kPersonBones = 11;
/// Number of person mesh variants (clothing and build).
constexpr int kPersonVariants = 4;

/// What a person is doing.
enum class Activity { kWalk, kStand, kSit };

/// Registers the person meshes ("person_0".."person_3") and returns their indices.
std::vector<int> buildPersonMeshes(MeshLibrary& meshes);

/// Bone matrices (kPersonBones) for an activity at animation phase `phase` (radians of the gait
/// or idle cycle). Sitting puts the hips at seat height 0.47 m above the object origin.
std::vector<Mat4> personPose(Activity activity, float phase);

}  // namespace world
}  // namespace viper
