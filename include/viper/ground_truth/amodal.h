// Amodal instance masks and visibility: the whole silhouette of every tracked object of a frame,
// occluded parts included, from its draws' meshes rasterised alone on the CPU with the recorded
// matrices (TriangleRasterizer: llvmpipe's rules), and from it the amodal box, the visible
// fraction, the truncation and KITTI's occlusion level and difficulty (docs/amodal.md).
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/step_problems.h"
#include "viper/ground_truth/triangle_raster.h"

#include <cstdint>
#include <vector>

namespace viper {

/// KITTI's occlusion levels.
enum class OcclusionLevel : uint8_t { kFullyVisible = 0, kPartlyOccluded = 1, kLargelyOccluded = 2, kUnknown = 3 };

/// KITTI's difficulty of a labelled object; kIgnored where it meets none of the three.
enum class Difficulty : uint8_t { kEasy = 0, kModerate = 1, kHard = 2, kIgnored = 3 };

/// Thresholds of the levels (defaults: docs/amodal.md says why).
struct AmodalOptions {
  /// Fully visible (level 0) at a visible fraction of at least this; partly occluded (1) at least
  /// `partly_visible`; below it, with any amodal pixel in the image, largely occluded (2).
  double fully_visible = 0.99;
  double partly_visible = 0.5;
};

/// One object's amodal mask and visibility.
struct AmodalObject {
  int32_t track_id = 0;
  uint8_t class_id = 0;
  /// The amodal box in the image (inclusive pixels, top row 0); empty if no pixel of the object
  /// falls in the image.
  PixelBox box;
  /// The amodal mask cropped to `box`: box.width() * box.height() bytes, row by row, 1 = the
  /// object covers the pixel (occluded or not), 0 = not.
  std::vector<uint8_t> mask;
  /// Pixels of the mask, and those of them where the instance image shows the object.
  uint32_t amodal_pixels = 0;
  uint32_t visible_pixels = 0;
  /// Pixels where the instance image shows the object but the mask does not cover (0 when the
  /// rasteriser and GL agree; a check, not part of visible_pixels).
  uint32_t visible_outside = 0;
  /// visible_pixels / amodal_pixels, 0 when the object has no amodal pixel.
  double visible_fraction = 0.0;
  /// Share of the object's projected 2D extent (its near-clipped silhouette's window box, image
  /// bounds not applied) outside the image: 1 - area(extent ∩ image) / area(extent), in [0, 1].
  double truncation = 0.0;
  OcclusionLevel occlusion = OcclusionLevel::kUnknown;
  Difficulty difficulty = Difficulty::kIgnored;

  /// Whether the mask covers image pixel (x, y).
  bool covers(int x, int y) const {
    return x >= box.x_min && x <= box.x_max && y >= box.y_min && y <= box.y_max &&
           mask[static_cast<size_t>(y - box.y_min) * box.width() + (x - box.x_min)] != 0;
  }
};

/// A frame's amodal objects, in the order of the tracked objects they come from.
struct FrameAmodal {
  uint32_t width = 0, height = 0;
  std::vector<AmodalObject> objects;
};

/// KITTI's occlusion level of a visible fraction (kUnknown where the object has no amodal pixel).
OcclusionLevel occlusionLevel(double visible_fraction, uint32_t amodal_pixels, const AmodalOptions& options);
/// KITTI's difficulty: easy at a box height of at least 40 px, level 0 and truncation at most
/// 0.15; moderate at 25 px, level <= 1, 0.30; hard at 25 px, level <= 2, 0.50; else ignored.
Difficulty kittiDifficulty(int box_height_px, OcclusionLevel occlusion, double truncation);

class AmodalStep {
 public:
  explicit AmodalStep(AmodalOptions options = AmodalOptions());

  /// One frame: every tracked object (track id > 0) of `objects` (the instances step's), its draws
  /// those of `frame`, rigid ones from the mesh store `meshes` and projection * view * world,
  /// deformed ones from their post-vertex-shader positions and their mesh's indices.
  /// `instance_ids` holds the frame's width * height track ids (the instances step's image).
  /// An object that cannot be drawn (a draw it names is not in the frame, a mesh never arrived,
  /// matrices missing or not finite, deformed positions that do not match the mesh) is named in
  /// `problems` and left out; without instance ids (null) the frame gives no object and says so.
  void process(const CaptureFrame& frame, const std::vector<TrackedObject>& objects, const int32_t* instance_ids,
               const MeshRegistry& meshes, FrameAmodal& out, StepProblems& problems);

  const AmodalOptions& options() const { return options_; }

 private:
  // Draws the object's triangles into raster_; false (with `why`) if a draw cannot be drawn.
  bool drawObject(const CaptureFrame& frame, const TrackedObject& object, const MeshRegistry& meshes,
                  std::string& why);
  AmodalOptions options_;
  TriangleRasterizer raster_;
};

}  // namespace viper
