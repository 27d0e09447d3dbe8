// Checks of a captured frame against itself, for programs that have no oracle (third-party games):
// every pixel that names a draw and a primitive must lie on that primitive once the recorded mesh
// is projected with the recorded matrices (or the recorded post-vertex-shader positions), at the
// depth the frame's depth image holds. One check covers draw ids, primitive ids, the mesh store,
// the world/view/projection matrices (uniforms, uniform blocks, instanced attributes) and the
// deformed vertices together.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/flow.h"
#include "viper/ground_truth/objects.h"

#include <cstdint>
#include <vector>

namespace viper {

/// What checkReprojection() found in one frame (or, added up, in several).
struct ReprojectionCheck {
  uint64_t pixels = 0;           ///< pixels of the frame
  uint64_t scene_pixels = 0;     ///< depth below 1 or a draw id (something was drawn there; the sky may be at depth 1)
  uint64_t id_pixels = 0;        ///< scene pixels with a draw id
  uint64_t placed_pixels = 0;    ///< id pixels whose draw has a mesh and its placement (matrices or deformed vertices)
  uint64_t checked_pixels = 0;   ///< placed pixels whose triangle is at least partly in front of the camera
  /// Per checked pixel: distance in pixels from the pixel's centre to its projected triangle (0 inside).
  std::vector<float> distance_px;
  /// Per checked pixel with a captured depth: |predicted - captured| / captured distance along the
  /// view axis.
  std::vector<float> depth_relative;
  /// Checked pixels whose captured window depth is 1 (the far plane: no surface, published as NaN),
  /// left out of depth_relative: a sky drawn on the far plane (gl_Position = p.xyww) is not at its
  /// mesh's depth, and has no depth to compare.
  uint64_t far_plane_pixels = 0;

  void add(const ReprojectionCheck& other);
};

/// The mesh a draw's pixels are placed on (checkReprojection(), the placed share): the draw's mesh
/// when `meshes` holds it and the draw has view and projection and either its world matrix or
/// deformed vertices (one per mesh vertex); nullptr when the draw is not placed.
const MeshRecord* placedMesh(const DrawRecord& draw, const MeshRegistry& meshes);

/// Projects, for every pixel with a draw id, the triangle its draw and primitive id name, and
/// measures how far the pixel lies from it and how far its depth is from the triangle's there.
/// Pixels whose draw lacks a mesh in `meshes`, a world, view or projection matrix (and has no
/// deformed vertices), or whose primitive id is out of range, are counted but not checked.
/// With `distance_image`: also per pixel, the distance of a checked pixel (NaN elsewhere).
ReprojectionCheck checkReprojection(const CaptureFrame& frame, const MeshRegistry& meshes,
                                    std::vector<float>* distance_image = nullptr);

/// What checkFlowPair() found for one pair of frames a, b (or, added up, for several).
struct FlowConsistencyCheck {
  /// Per pixel of a with forward flow that lands inside b and is visible there: the endpoint of
  /// going forward and then back, |F(x) + B(x + F(x))| in pixels (B bilinear where its four
  /// neighbours are defined, else nearest).
  std::vector<float> forward_backward_px;
  /// Over the same pixels: mean absolute difference of the color (0..255, mean over R, G, B) of a
  /// at x and of b at x + F(x) (bilinear), and of b at x (no motion), to compare against.
  double photometric_flow_sum = 0.0, photometric_zero_sum = 0.0;
  uint64_t photometric_pixels = 0;
  uint64_t flow_pixels = 0;     ///< pixels of a with a defined forward flow
  uint64_t visible_pixels = 0;  ///< of those, visible in b and inside it
  uint64_t id_pixels = 0;       ///< pixels of a with a draw id

  void add(const FlowConsistencyCheck& other);
  double photometricFlow() const { return photometric_pixels ? photometric_flow_sum / photometric_pixels : 0.0; }
  double photometricZero() const { return photometric_pixels ? photometric_zero_sum / photometric_pixels : 0.0; }
};

/// Checks the flow a -> b against the flow b -> a and against the images: where the forward flow
/// says a point is visible in b, going back from where it lands must return to it, and b's color
/// there must be a's. Sizes must agree (else nothing is counted).
FlowConsistencyCheck checkFlowPair(const CaptureFrame& a, const CaptureFrame& b, const FlowField& forward,
                                   const FlowField& backward);

/// What checkStaticFlow() found for one pair of frames (or, added up, for several).
struct StaticFlowCheck {
  /// Per pixel of a static surface with forward flow: |flow - ego flow| in pixels.
  std::vector<float> error_px;
  uint64_t static_pixels = 0;  ///< pixels of a whose draw is static (with or without flow)
  void add(const StaticFlowCheck& other);
};

/// Checks the flow a -> b of static surfaces against the camera's own motion. A draw of a is static
/// when it is rigid (no deformed vertices) and `a_to_b` associates it with a draw of b that has
/// the same mesh and the same world matrix; both must carry view and projection. For each of its
/// pixels with forward flow, the point at the pixel's centre and depth (a's depth image,
/// unprojected with the draw's projection and view in a) is projected with the b draw's view and
/// projection: that displacement (the ego flow) is what the flow must be. Independent of the
/// meshes the flow was computed from; it checks them against the depth image.
StaticFlowCheck checkStaticFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                                const FlowField& forward);

/// What checkBoxes() found in one frame (or, added up, in several).
struct BoxCheck {
  uint64_t objects = 0;  ///< objects with a box and pixels
  uint64_t pixels = 0;   ///< their pixels with depth and their draw's view and projection
  /// Per such pixel: how far its point lies outside its object's box, relative to the point's
  /// distance from the camera (0 inside).
  std::vector<float> outside_relative;
  /// The pixel farthest outside its box (relative 0: none outside): where it is, whose draw, and
  /// whether its point lies beyond the box's centre as seen from the camera (depth from a surface
  /// behind the object) or before it (depth from a surface in front that wrote no id).
  struct Outlier {
    float relative = 0.0f;
    uint64_t frame = 0;
    uint32_t draw = 0, col = 0, row = 0;
    bool beyond = false;
  } worst;
  void add(const BoxCheck& other);
};

/// Checks the objects' oriented boxes (objectBox: from the meshes and matrices) against the image:
/// the point of every pixel of an object (its depth, unprojected with the projection and view of
/// the draw that drew it) must lie inside the object's box. The depth image comes from the
/// program's rasteriser, not from the meshes, so parts missing from a box, a wrong world matrix or
/// wrongly attached parts show as points outside.
BoxCheck checkBoxes(const CaptureFrame& frame, const std::vector<FrameObject>& objects, const MeshRegistry& meshes);

/// The q-quantile (0..1) of `values` without its NaNs (a copy is partially sorted); NaN when none is left.
float quantile(std::vector<float> values, double q);

/// What the capture layer reported it could not record, summed over frames: draws with each
/// DrawGaps bit (and the pixels they own), and CaptureFrame::unrecorded_draws.
struct CaptureGaps {
  uint64_t draws = 0, unrecorded_draws = 0;
  uint64_t no_ids = 0, matrix_missing = 0, no_mesh = 0;
  uint64_t matrix_missing_pixels = 0, no_mesh_pixels = 0;
  void add(const CaptureFrame& frame);
};

}  // namespace viper
