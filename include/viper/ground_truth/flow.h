// Dense optical flow and correspondences between two captured frames (docs/flow_node.md): rigid
// surfaces by lifting depth through the inverse of projection * view * world; non-rigid surfaces
// by inverting the rasterizer's perspective-correct interpolation over the triangle's
// post-vertex-shader positions. No image is resampled.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/instructions.h"

#include <cstdint>
#include <vector>

namespace viper {

/// For each draw of frame `a`, the index of the draw of frame `b` that shows the same surface, or
/// -1. `a_object_ids[i]` is a stable identity of draw i's object (its track id), 0 if it has none.
/// Draws of tracked objects associate by (object id, mesh key); other draws by (mesh key, world
/// matrix), and failing that by a mesh key that occurs once in each frame.
std::vector<int32_t> associateDraws(const CaptureFrame& a, const std::vector<int32_t>& a_object_ids,
                                    const CaptureFrame& b, const std::vector<int32_t>& b_object_ids);

/// Flow from frame a to frame b.
struct FlowField {
  uint32_t width = 0, height = 0;
  /// Interleaved (u, v) in pixels (u right, v down); NaN where undefined (no surface, no
  /// association, missing geometry, the point not in front of b's near plane).
  std::vector<float> uv;
  /// 255 where the corresponding point is visible in frame b (inside it and not behind b's depth),
  /// 0 where it is occluded, out of view or undefined.
  std::vector<uint8_t> visible;
};

/// Counts of what happened to the pixels of one flow computation.
struct FlowStats {
  size_t rigid = 0, non_rigid = 0;   ///< pixels with flow, by kind
  size_t no_surface = 0;             ///< no draw, or no depth
  size_t no_association = 0;         ///< the draw has no counterpart in frame b
  size_t missing_geometry = 0;       ///< deformed draw without positions / mesh, or singular matrices
  /// Pixels whose surface point is not in front of b's near plane (b's camera passed it, or is
  /// about to): b's camera cannot image the point, and its projection runs off to infinity at the
  /// camera plane.
  size_t behind_b = 0;
  /// Pixels of a draw without depth (not in [0, 1) as window depth; not positive and finite as
  /// metres, or no projection to read them with) where the same draw has depth elsewhere: a draw
  /// with none at all is a background (a sky), not an error. Also counted in no_surface.
  size_t no_depth = 0;
};

/// The instructions that compute a row's pixels in blocks (instructions.h). Every path gives the
/// same flow: AVX-512 (16 pixels a step) and AVX2 (8) bit for bit; one pixel at a time (kScalar,
/// also used at the end of each row) differs from them by float rounding, as it fuses no
/// multiply-adds.
using FlowInstructions = Instructions;

/// The path computeFlow takes on this CPU when asked for `requested` (instructionsUsed; flow has no
/// kAvx512Vbmi path of its own: that is kAvx512).
inline FlowInstructions flowInstructionsUsed(FlowInstructions requested) {
  const Instructions used = instructionsUsed(requested);
  return used == Instructions::kAvx512Vbmi ? Instructions::kAvx512 : used;
}

/// Options of computeFlow.
struct FlowOptions {
  /// A point is visible in b when b's depth there is at least the point's depth minus
  /// (relative * depth + absolute).
  double occlusion_relative = 0.005;
  double occlusion_absolute_m = 0.02;
  /// Which instructions compute the pixels (for comparing the paths; the default is fastest).
  FlowInstructions instructions = FlowInstructions::kWidest;
};

/// A frame's pixels as computeFlow reads them, wherever they are stored (a CaptureFrame's vectors,
/// or the messages the frame came in): width*height draw ids, primitive ids, and depths, either
/// as window depth (as captured) or in metres along the optical axis (REP 118, NaN = no surface; as
/// the depth topic carries them). Only frame a's ids and depth are read.
///
/// Metres are read as they are: a draw's flow comes from its forms in 1 / metres where its
/// projection has P33 = 0 (every perspective one), with no per-pixel conversion. Under other
/// projections each pixel's metres are turned into window depth first, as windowDepthFromMetres
/// does (the draw's own projection, or `depth_projection` for draws without one; neither: no flow).
struct FlowFramePixels {
  uint32_t width = 0, height = 0;
  const std::vector<DrawRecord>* draws = nullptr;
  const uint32_t* draw_ids = nullptr;
  const uint32_t* primitive_ids = nullptr;
  const float* depth_window = nullptr;  ///< window depth in [0, 1); or
  const float* depth_metres = nullptr;  ///< metres (exactly one of the two)
  const GlMatrix* depth_projection = nullptr;  ///< with depth_metres: for draws without a projection
};
/// The pixels of `frame`; throws std::invalid_argument if an image does not hold width*height values.
FlowFramePixels flowFramePixels(const CaptureFrame& frame);

/// Computes flow a -> b into caller storage: `uv` holds 2*width*height floats, `visible`
/// width*height bytes (a message's buffers, say); `b_depth_m` width*height metres. Only b's size
/// and draws are read. Otherwise as below.
void computeFlow(const FlowFramePixels& a, const FlowFramePixels& b, const std::vector<int32_t>& a_to_b,
                 const float* b_depth_m, const MeshRegistry& meshes, float* uv, uint8_t* visible,
                 const FlowOptions& options = FlowOptions(), FlowStats* stats = nullptr);

/// Computes flow a -> b. `a_to_b` comes from associateDraws; `b_depth_m` is b's depth in metres
/// along the optical axis (NaN = no surface), width*height values; `meshes` holds the triangles
/// of deformed draws. Throws std::invalid_argument if the frames' sizes differ, or a vector size
/// does not match its frame.
FlowField computeFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                      const std::vector<float>& b_depth_m, const MeshRegistry& meshes,
                      const FlowOptions& options = FlowOptions(), FlowStats* stats = nullptr);
/// The same, writing into `out` (its buffers are reused when the size is unchanged).
void computeFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                 const std::vector<float>& b_depth_m, const MeshRegistry& meshes, FlowField& out,
                 const FlowOptions& options = FlowOptions(), FlowStats* stats = nullptr);

}  // namespace viper
