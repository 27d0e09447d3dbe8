#include "people.h"

#include "classes.h"

#include <cmath>

namespace viper {
namespace world {

namespace {
// Joint positions of the bind pose (standing, facing +x) and each bone's parent.
const Vec3 kJoint[kPersonBones] = {
    {0, 0, 0.95f},   {0, 0, 1.0f},     {0, 0, 1.5f},     {0, 0.21f, 1.43f}, {0, 0.23f, 1.14f},
    {0, -0.21f, 1.43f}, {0, -0.23f, 1.14f}, {0, 0.1f, 0.92f}, {0, 0.1f, 0.5f}, {0, -0.1f, 0.92f},
    {0, -0.1f, 0.5f}};
const int kParent[kPersonBones] = {-1, 0, 1, 1, 3, 1, 5, 0, 7, 0, 9};

struct Outfit { Vec3 shirt, pants, skin; float build; };
const Outfit kOutfits[kPersonVariants] = {
    {{0.7f, 0.15f, 0.12f}, {0.15f, 0.18f, 0.3f}, {0.85f, 0.65f, 0.5f}, 1.0f},
    {{0.2f, 0.35f, 0.6f}, {0.25f, 0.22f, 0.2f}, {0.55f, 0.38f, 0.26f}, 1.1f},
    {{0.85f, 0.8f, 0.3f}, {0.1f, 0.1f, 0.12f}, {0.9f, 0.75f, 0.62f}, 0.9f},
    {{0.3f, 0.55f, 0.3f}, {0.45f, 0.4f, 0.35f}, {0.4f, 0.28f, 0.2f}, 1.0f}};

MeshData personMesh(const Outfit& o) {
  MeshData m;
  m.current_bone = 0;  // marks the mesh as skinned from the first vertex on
  float b = o.build;
  auto box = [&](int bone, Vec3 c, Vec3 h, Vec3 col) {
    m.current_bone = bone;
    m.addBox(translation(c), h, col);
  };
  box(0, {0, 0, 0.95f}, {0.11f * b, 0.17f * b, 0.09f}, o.pants);
  box(1, {0, 0, 1.22f}, {0.12f * b, 0.19f * b, 0.22f}, o.shirt);
  box(2, {0.01f, 0, 1.62f}, {0.1f, 0.085f, 0.12f}, o.skin);
  box(2, {-0.01f, 0, 1.73f}, {0.1f, 0.09f, 0.03f}, o.pants * 0.6f);  // hair
  for (int side = 0; side < 2; ++side) {
    float s = side ? -1.0f : 1.0f;
    box(3 + 2 * side, {0, s * 0.24f, 1.29f}, {0.05f, 0.05f, 0.15f}, o.shirt);
    box(4 + 2 * side, {0, s * 0.24f, 1.0f}, {0.045f, 0.045f, 0.15f}, o.skin);
    box(7 + 2 * side, {0, s * 0.1f, 0.71f}, {0.07f, 0.07f, 0.21f}, o.pants);
    box(8 + 2 * side, {0, s * 0.1f, 0.27f}, {0.06f, 0.06f, 0.23f}, o.pants);
    box(8 + 2 * side, {0.05f, s * 0.1f, 0.03f}, {0.12f, 0.055f, 0.03f}, {0.1f, 0.08f, 0.06f});
  }
  // Vertices of lower limbs near their joint are shared half-and-half with the parent, so knees
  // and elbows bend smoothly.
  for (size_t v = 0; v < m.vertexCount(); ++v) {
    int bone = int(m.bone_ids[4 * v]);
    if (bone != 4 && bone != 6 && bone != 8 && bone != 10) continue;
    if (m.positions[3 * v + 2] < kJoint[bone].z - 0.1f) continue;
    m.bone_ids[4 * v + 1] = float(kParent[bone]);
    m.bone_weights[4 * v] = 0.5f;
    m.bone_weights[4 * v + 1] = 0.5f;
  }
  return m;
}
}  // namespace

std::vector<int> buildPersonMeshes(MeshLibrary& meshes) {
  std::vector<int> out;
  for (int i = 0; i < kPersonVariants; ++i)
    out.push_back(meshes.add("person_" + std::to_string(i), kPerson, personMesh(kOutfits[i])));
  return out;
}

std::vector<Mat4> personPose(Activity activity, float phase) {
  float rot[kPersonBones] = {};  // pitch of each bone relative to its parent (about y)
  Vec3 root{0, 0, 0};
  float roll_arms = 0.05f;
  if (activity == Activity::kWalk) {
    float s = std::sin(phase);
    rot[7] = -0.45f * s;
    rot[9] = 0.45f * s;
    rot[8] = 0.5f * std::max(0.0f, std::sin(phase + 1.2f));
    rot[10] = 0.5f * std::max(0.0f, std::sin(phase + 1.2f + kPi));
    rot[3] = 0.35f * s;
    rot[5] = -0.35f * s;
    rot[4] = rot[6] = -0.3f;
    rot[1] = -0.05f;
    root.z = 0.03f * std::fabs(std::cos(phase));
  } else if (activity == Activity::kStand) {
    rot[3] = 0.05f * std::sin(phase);
    rot[5] = -0.05f * std::sin(phase);
    rot[1] = 0.03f * std::sin(phase * 0.5f);
    rot[2] = 0.1f * std::sin(phase * 0.3f);
  } else {
    rot[7] = rot[9] = -kPi * 0.5f;
    rot[8] = rot[10] = kPi * 0.5f;
    rot[3] = rot[5] = -0.5f;
    rot[4] = rot[6] = -0.6f;
    rot[2] = 0.1f * std::sin(phase * 0.3f);
    root.z = 0.47f + 0.1f - kJoint[0].z;
  }
  std::vector<Mat4> global(kPersonBones), skin(kPersonBones);
  for (int b = 0; b < kPersonBones; ++b) {
    Mat4 local_rot = rotationY(rot[b]);
    if (b == 3 || b == 4) local_rot = local_rot * rotationX(roll_arms);
    if (b == 5 || b == 6) local_rot = local_rot * rotationX(-roll_arms);
    if (b == 2 && activity == Activity::kStand) local_rot = rotationZ(rot[2]);
    if (kParent[b] < 0) {
      global[b] = translation(kJoint[b] + root) * local_rot;
    } else {
      global[b] = global[kParent[b]] * translation(kJoint[b] - kJoint[kParent[b]]) * local_rot;
    }
    skin[b] = global[b] * translation(kJoint[b] * -1.0f);
  }
  return skin;
}

}  // namespace world
}  // namespace viper
