// Writes one sequence's ground truth, frame by frame, in the formats training frameworks read
// (Cityscapes gtFine, COCO instance JSON, KITTI flow and depth PNGs) under one root folder, from the
// per-frame core results: camera image, class ids, instance ids, forward flow, depth. The
// export_training command hands it a recorded bag's messages; `generate` can hand it the
// ground-truth pipeline's results. docs/training_formats.md. ROS-free.
#pragma once

#include "viper/dataset/coco.h"
#include "viper/dataset/flow_image.h"
#include "viper/dataset/viper_images.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace viper::dataset {

/// Settings of a training-format export.
struct TrainingExportOptions {
  std::string root;                 ///< created
  bool cityscapes = true;           ///< <root>/cityscapes/{gtFine,leftImg8bit}/<split>/<city>/...
  bool coco = true;                 ///< <root>/coco/annotations/instances[_amodal]_<split>_<seq>.json (+ images)
  bool kitti = true;                ///< <root>/kitti/<split>/<seq>/{flow_occ,proj_depth/groundtruth/image_02}
  std::string split = "train";      ///< no '/'
  std::string city = "viper";       ///< Cityscapes' city: no '_', no '/'
  uint32_t sequence = 1;            ///< 0..999999
  std::vector<CocoCategory> categories;  ///< COCO categories (VIPER class ids); empty = every class seen is left out
  ImageWriteOptions images;
};

/// One object's amodal mask (its whole silhouette, occluded parts included) in a box of the image:
/// what the amodal step's AmodalObject holds (box x_min, y_min, width, height; its cropped mask).
struct TrainingAmodalMask {
  int64_t track_id = 0;
  int class_id = 0;                 ///< VIPER class id
  int box_x = 0, box_y = 0;         ///< the box's top-left pixel
  uint32_t box_width = 0, box_height = 0;
  const uint8_t* mask = nullptr;    ///< box_width * box_height bytes, row by row, non-zero = covered
};

/// One frame's inputs; each may be absent (null / empty), and the formats that need it skip it.
struct TrainingFrame {
  uint32_t frame = 0;                      ///< 0..999999
  const ImageView8* rgb = nullptr;         ///< the camera image, 3 channels
  const uint8_t* class_ids = nullptr;      ///< VIPER class ids, width * height
  const int32_t* instance_ids = nullptr;   ///< width * height, 0 = none
  uint32_t width = 0, height = 0;          ///< of class_ids / instance_ids
  const FlowImage* flow = nullptr;         ///< forward flow, frame -> frame + 1
  const float* depth_m = nullptr;          ///< width * height metres (NaN: none)
  /// Amodal masks: with any, COCO's amodal file gets this frame's image and one annotation each.
  const std::vector<TrainingAmodalMask>* amodal = nullptr;
};

/// Files and values written.
struct TrainingExportStats {
  size_t cityscapes_frames = 0, coco_images = 0, coco_annotations = 0, coco_skipped_objects = 0;
  size_t coco_amodal_annotations = 0;
  size_t kitti_flow = 0, kitti_depth = 0;
  size_t kitti_flow_out_of_range = 0, kitti_depth_out_of_range = 0;  ///< values written invalid
  size_t cityscapes_group_pixels = 0, cityscapes_instances_over_limit = 0;
};

/// Writes frames as they come, and the COCO file at finish().
class TrainingExport {
 public:
  /// Throws std::invalid_argument for a bad split, city or sequence.
  explicit TrainingExport(TrainingExportOptions options);

  /// Writes the formats this frame has inputs for: Cityscapes and COCO need class and instance ids
  /// (and write the image when `rgb` is given), KITTI flow the flow, KITTI depth the depth. Throws
  /// std::invalid_argument for sizes that disagree, std::runtime_error naming a file that cannot be
  /// written.
  void addFrame(const TrainingFrame& frame);

  /// Writes the COCO files (when coco is on and an image was added; the amodal one when a frame had
  /// amodal masks). Call once, at the end.
  void finish();

  const TrainingExportStats& stats() const { return stats_; }

 private:
  TrainingExportOptions options_;
  std::optional<CocoInstancesWriter> coco_, coco_amodal_;
  TrainingExportStats stats_;
};

}  // namespace viper::dataset
