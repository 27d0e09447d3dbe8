// Cityscapes' fine ground truth (gtFine) from VIPER's class and instance ids, in Cityscapes' folder
// layout and encodings, as cityscapesScripts writes and reads them (helpers/labels.py,
// preparation/json2labelImg.py, json2instanceImg.py, createTrainIdLabelImgs.py):
//   gtFine/SPLIT/CITY/CITY_SSSSSS_FFFFFF_gtFine_labelIds.png       8-bit gray, label ids
//   gtFine/SPLIT/CITY/CITY_SSSSSS_FFFFFF_gtFine_labelTrainIds.png  8-bit gray, train ids (255 ignored)
//   gtFine/SPLIT/CITY/CITY_SSSSSS_FFFFFF_gtFine_instanceIds.png    16-bit gray: label id * 1000 + k
//       for the k-th instance (k from 0) of a label with instances, the label id elsewhere
//   gtFine/SPLIT/CITY/CITY_SSSSSS_FFFFFF_gtFine_color.png          8-bit RGBA, the labels' colors
//   leftImg8bit/SPLIT/CITY/CITY_SSSSSS_FFFFFF_leftImg8bit.png      8-bit RGB, the camera image
// VIPER's classes map to Cityscapes' labels by cityscapesLabelOfViperClass (table and reasons in
// docs/training_formats.md). ROS-free.
#pragma once

#include "viper/dataset/viper_images.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

/// One row of cityscapesScripts' label table (helpers/labels.py).
struct CityscapesLabel {
  int id = 0;                 ///< 0..33
  const char* name = "";
  int train_id = 255;         ///< 255: not trained on
  bool has_instances = false;
  bool ignore_in_eval = true;
  std::array<uint8_t, 3> color{{0, 0, 0}};
};

/// Cityscapes' labels 0..33, indexed by id (the label 'license plate', id -1, is left out: it is
/// never in the ground-truth images).
const std::vector<CityscapesLabel>& cityscapesLabels();

/// The Cityscapes label id of a VIPER class id (config/viper_classes.csv, 0..31); ids beyond the
/// table get 0 ('unlabeled').
uint8_t cityscapesLabelOfViperClass(int viper_class_id);

/// One frame's ground truth in Cityscapes' encodings, width * height values each, rows from the top.
struct CityscapesGroundTruth {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> label_ids;      ///< labelIds
  std::vector<uint8_t> train_ids;      ///< labelTrainIds
  std::vector<uint16_t> instance_ids;  ///< instanceIds
  std::vector<uint8_t> color_rgba;     ///< color, 4 bytes a pixel (alpha 255)
  /// Pixels of a label with instances but no VIPER instance id (0): written as the label id, as
  /// Cityscapes writes its groups ('cargroup'), which its evaluation ignores.
  size_t group_pixels = 0;
  /// Instances beyond the 1000th of one label (Cityscapes' encoding holds 0..999): their pixels are
  /// written as groups too.
  size_t instances_over_limit = 0;
};

/// Converts VIPER's per-pixel class ids and instance ids (0 = no instance) into Cityscapes'
/// encodings. Instances of one Cityscapes label are numbered k = 0, 1, ... in the order of their
/// VIPER instance ids (a VIPER car and van, both Cityscapes 'car', share the numbering); an instance
/// id of a label without instances is dropped (the pixel gets the label id). Throws
/// std::invalid_argument for a null pointer with non-zero sizes.
CityscapesGroundTruth cityscapesGroundTruth(const uint8_t* viper_class_ids, const int32_t* instance_ids,
                                            uint32_t width, uint32_t height);

/// Where a frame goes: Cityscapes names its files CITY_SEQ_FRAME with 6-digit numbers.
struct CityscapesFrameName {
  std::string split = "train";  ///< train, val, test
  std::string city = "viper";   ///< no '_' and no '/' (readers split the file name at '_')
  uint32_t sequence = 0;        ///< 0..999999
  uint32_t frame = 0;           ///< 0..999999

  /// "CITY_SSSSSS_FFFFFF". Throws std::invalid_argument for a city with '_' or '/', or an empty one,
  /// or numbers over 6 digits.
  std::string stem() const;
};

/// Writes a frame's gtFine files (labelIds, labelTrainIds, instanceIds, color) under `root`, and
/// its leftImg8bit image when `left_rgb` is not null (3 channels, the ground truth's size),
/// creating the folders. Each file is written under a temporary name and renamed. Throws
/// std::invalid_argument for a bad name or sizes, std::runtime_error naming the file if it cannot
/// be written.
void writeCityscapesFrame(const std::string& root, const CityscapesFrameName& name,
                          const CityscapesGroundTruth& gt, const ImageView8* left_rgb,
                          const ImageWriteOptions& options = ImageWriteOptions());

}  // namespace viper::dataset
