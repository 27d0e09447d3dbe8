// Dense scene flow between two captured frames (docs/flow_node.md, "Scene flow"): per pixel of
// frame a, the 3D displacement of its surface point from a to b in a's optical frame, and the
// change of its depth. The same surface point as the optical flow a -> b (flow.h), defined where
// that flow is.
#pragma once

#include "viper/ground_truth/flow.h"

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace viper {

/// Floats per pixel of a scene flow: (dx, dy, dz, d_depth).
constexpr size_t kSceneFlowChannels = 4;

/// Counts of one scene flow computation.
struct SceneFlowStats {
  size_t defined = 0;  ///< pixels with a scene flow (every pixel with an optical flow)
  /// Pixels with an optical flow for which the surface point could not be formed again (a's
  /// matrices not invertible in double, say): NaN there. 0 on every capture the tests read.
  size_t unformed = 0;
};

/// b's optical coordinates into a's, from the OpenGL view matrices of frames a and b (world to
/// camera): the product of view_a and the full inverse of view_b in double, as the floats are. Not
/// opticalFromWorld(view_a) * opticalFromWorld(view_b).inverse(), whose inverse transposes a
/// rotation that float rounding left not quite orthonormal: with a camera hundreds of metres from
/// the world's origin that moved points the world holds still by 1e-5 of their depth.
Eigen::Isometry3d opticalMotion(const GlMatrix& view_a, const GlMatrix& view_b);

/// Scene flow a -> b into `xyzd`, kSceneFlowChannels floats per pixel of a (a message's buffer, say):
/// - (dx, dy, dz): the surface point's position in b minus its position in a, metres, in a's
///   optical frame (REP 103: x right, y down, z forward). A point that does not move in the world
///   has (0, 0, 0), whatever the camera does: the camera's own motion is not in it.
/// - d_depth: the point's depth along b's optical axis in b minus its depth along a's in a, metres
///   (Infinigen's depth change): a's depth plus d_depth is the point's depth in b, which b's depth
///   image shows where the flow's mask says the point is visible in b.
/// All four are NaN exactly where `uv` (the optical flow a -> b that computeFlow gave for the same
/// inputs: 2 floats per pixel) is NaN, so the flow's mask and its reasons (FlowStats) are the scene
/// flow's; the flow's visibility mask applies as it is.
///
/// The surface point is computeFlow's: rigid draws lift a's depth through the inverse of
/// projection * view * world of a and carry the object point with b's view * world; deformed draws
/// take the pixel centre's perspective-correct barycentrics in its triangle of a's post-vertex-shader
/// positions to b's, and into each frame's camera coordinates through the draw's projection.
/// `a_from_b` takes b's optical coordinates into a's: opticalMotion() of the frames' cameras.
/// Computed in double, one pixel at a time, after the flow.
/// Throws std::invalid_argument as computeFlow does, or if `uv` or `xyzd` is null.
void computeSceneFlow(const FlowFramePixels& a, const FlowFramePixels& b, const std::vector<int32_t>& a_to_b,
                      const MeshRegistry& meshes, const Eigen::Isometry3d& a_from_b, const float* uv, float* xyzd,
                      SceneFlowStats* stats = nullptr);

/// The same for two CaptureFrames (their window depth): `flow` is computeFlow's flow a -> b;
/// returns width*height*kSceneFlowChannels floats.
std::vector<float> computeSceneFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                                   const MeshRegistry& meshes, const Eigen::Isometry3d& a_from_b,
                                   const FlowField& flow, SceneFlowStats* stats = nullptr);

}  // namespace viper
