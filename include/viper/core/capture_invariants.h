// Checks of a captured frame against itself, for programs that have no oracle (third-party games):
// every pixel that names a draw and a primitive must lie on that primitive once the recorded mesh
// is projected with the recorded matrices (or the recorded post-vertex-shader positions), at the
// depth the frame's depth image holds. One check covers draw ids, primitive ids, the mesh store,
// the world/view/projection matrices (uniforms, uniform blocks, instanced attributes) and the
// deformed vertices together.
#pragma once

#include "viper/core/capture_frame.h"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace viper {

/// Meshes by key: the union of CaptureFrame::new_meshes over a stream so far.
using MeshStore = std::unordered_map<uint64_t, MeshRecord>;

/// What checkReprojection() found in one frame (or, added up, in several).
struct ReprojectionCheck {
  uint64_t pixels = 0;           ///< pixels of the frame
  uint64_t scene_pixels = 0;     ///< depth below 1 or a draw id (something was drawn there; the sky may be at depth 1)
  uint64_t id_pixels = 0;        ///< scene pixels with a draw id
  uint64_t placed_pixels = 0;    ///< id pixels whose draw has a mesh and its placement (matrices or deformed vertices)
  uint64_t checked_pixels = 0;   ///< placed pixels whose triangle is at least partly in front of the camera
  /// Per checked pixel: distance in pixels from the pixel's centre to its projected triangle (0 inside).
  std::vector<float> distance_px;
  /// Per checked pixel: |predicted - captured| / captured distance along the view axis.
  std::vector<float> depth_relative;

  void add(const ReprojectionCheck& other);
};

/// Projects, for every pixel with a draw id, the triangle its draw and primitive id name, and
/// measures how far the pixel lies from it and how far its depth is from the triangle's there.
/// Pixels whose draw lacks a mesh in `meshes`, a world, view or projection matrix (and has no
/// deformed vertices), or whose primitive id is out of range, are counted but not checked.
ReprojectionCheck checkReprojection(const CaptureFrame& frame, const MeshStore& meshes);

/// The q-quantile (0..1) of `values` without its NaNs (a copy is partially sorted); NaN when none is left.
float quantile(std::vector<float> values, double q);

}  // namespace viper
