// Surface normals per pixel (docs/ground_truth_nodes.md, "Normals"): the geometric normal of the
// triangle under each pixel, named by the frame's draw and primitive ids, in the optical frame of the
// frame's camera. The normals node (src/ros/ground_truth/normals_node.cpp) and the lockstep `generate`
// both run NormalsStep.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/step_problems.h"

#include <cstddef>
#include <optional>

namespace viper {

/// Counts of what happened to the pixels of one normals computation.
struct NormalStats {
  size_t with_normal = 0;        ///< pixels given a normal
  size_t no_surface = 0;         ///< no draw, or no depth there (a background at the far plane)
  size_t missing_mesh = 0;       ///< the draw's mesh is not in the mesh store
  size_t missing_deformed = 0;   ///< deformed draw whose post-vertex-shader positions do not fit its mesh
  size_t bad_primitive = 0;      ///< primitive id past the mesh's triangles, or a vertex index past its vertices
  size_t degenerate = 0;         ///< the triangle has no area (or its matrices are not finite / invertible)
  /// Draws (index) of the first pixel of each failure kind above, -1 for none: for the problems' text.
  long first_missing_mesh = -1, first_missing_deformed = -1, first_bad_primitive = -1;
};

/// Computes the normal of every pixel into `out` (3 floats a pixel, x y z, row-major, top row
/// first: a 32FC3 image's data). A pixel's normal is that of its triangle (draw id - 1, primitive id)
/// as drawn: rigid draws from the mesh store's object-space positions through the draw's world
/// matrix and the camera's view (a draw without a view of its own: through its world matrix alone,
/// the program's model-view); deformed draws from their post-vertex-shader clip positions through the
/// inverse of the draw's projection (the camera's where it has none), and of its view. It is
/// expressed in `camera`'s optical frame (REP 103: x right, y down, z forward), of unit length and
/// turned towards the camera (n . d < 0 for the pixel's viewing ray d). NaN where there is no draw,
/// no depth (`in.depth_m` not positive and finite: no surface), or the triangle cannot be found
/// (counted in `stats`). `in`'s draw ids, primitive ids and depth must not be null.
void computeNormals(const GroundTruthInput& in, const FrameCamera& camera, const MeshRegistry& meshes, float* out,
                    NormalStats* stats = nullptr);

/// The viewing ray through pixel (u, v) in the optical frame of `camera` for a width x height image:
/// K^-1 (u, v, 1) under a perspective projection, (0, 0, 1) under any other.
class PixelRays {
 public:
  PixelRays(const FrameCamera& camera, uint32_t width, uint32_t height);
  float x(uint32_t u) const { return perspective_ ? (static_cast<float>(u) - cx_) * inv_fx_ : 0.0f; }
  float y(uint32_t v) const { return perspective_ ? (static_cast<float>(v) - cy_) * inv_fy_ : 0.0f; }

 private:
  bool perspective_ = false;
  float cx_ = 0, cy_ = 0, inv_fx_ = 0, inv_fy_ = 0;
};

/// The normals node's per-frame work: checks the frame, computes its normals, and says what was
/// wrong with its inputs.
class NormalsStep {
 public:
  /// One frame into `out` (3 * width * height floats). `camera` is the frame's (chooseFrameCamera),
  /// `meshes` every mesh so far. Every pixel is written. Returns false (every pixel NaN) when the
  /// frame has no normals: ids or depth missing (null), no camera, draw ids past the draws; else
  /// true, with draws whose triangles cannot be found (no mesh, deformed without its positions,
  /// primitive ids past the mesh) named in `problems` and their pixels NaN.
  bool process(const GroundTruthInput& in, const std::optional<FrameCamera>& camera, const MeshRegistry& meshes,
               float* out, StepProblems& problems, NormalStats* stats = nullptr) const;
};

}  // namespace viper
