// COCO instance segmentation JSON (the "instances_*.json" that detection frameworks read): images,
// categories and one annotation per object and frame with its mask as COCO's compressed RLE,
// exactly as the COCO API's maskApi (pycocotools.mask.encode) writes it, its bbox, area, iscrowd 0
// and its track id. Masks come from a frame's instance ids (visible masks) or from any per-object
// mask in a box (amodal masks). docs/training_formats.md. ROS-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

/// A mask as COCO's run-length encoding: `counts` alternate runs of 0 and 1 (the first run is of
/// 0s, possibly empty) over the pixels in column-major order (down each column, columns from the
/// left), summing to height * width.
struct CocoRle {
  uint32_t height = 0;
  uint32_t width = 0;
  std::vector<uint32_t> counts;
};

/// The RLE of a mask given inside a box of an image of `width` x `height`: `mask` holds
/// box_width * box_height bytes row by row (non-zero = inside) for the pixels from (box_x, box_y);
/// parts of the box outside the image are left out. `mask` may be null when the box is empty.
CocoRle cocoRleOfBoxMask(uint32_t width, uint32_t height, int box_x, int box_y, uint32_t box_width,
                         uint32_t box_height, const uint8_t* mask);

/// COCO's compressed RLE string of `rle` (maskApi's rleToString: each count, from the third on as
/// the difference to the count two before, in 5-bit groups with a continuation bit, + 48).
std::string cocoRleString(const CocoRle& rle);

/// The mask's pixel count (maskApi's rleArea).
uint64_t cocoRleArea(const CocoRle& rle);

/// The mask's tight box [x, y, width, height] in pixels (maskApi's rleToBbox); all 0 for an empty
/// mask.
std::vector<uint32_t> cocoRleBox(const CocoRle& rle);

/// One category of the file.
struct CocoCategory {
  int id = 0;
  std::string name;
  std::string supercategory;
};

/// One object's mask in one image, for CocoInstancesWriter::addAnnotation.
struct CocoObjectMask {
  int category_id = 0;
  int64_t track_id = 0;  ///< the object's id across frames (VIPER's instance / track id)
  CocoRle rle;
};

/// Collects images and annotations and writes them as one COCO JSON file. Image ids are 1, 2, ...
/// in the order added, annotation ids too.
class CocoInstancesWriter {
 public:
  /// `categories`: the categories written; objects of other classes are left out (and counted).
  explicit CocoInstancesWriter(std::vector<CocoCategory> categories);

  /// Adds an image: its file name (relative to the images' folder), size, and where it belongs
  /// (written as the image's "sequence" and "frame_index", for video-aware readers). Returns its id.
  int addImage(const std::string& file_name, uint32_t width, uint32_t height, const std::string& sequence,
               int64_t frame_index);

  /// Adds one annotation per instance id (non-zero) of the image's `instance_ids` (width * height,
  /// row-major): its visible mask, category = the most frequent of its pixels' `class_ids` (the
  /// category ids are VIPER class ids), track id = the instance id. Instances of classes that are
  /// not categories are left out (skipped_objects()). Throws std::invalid_argument for an unknown
  /// image id or null pixels.
  void addVisibleInstances(int image_id, const uint8_t* class_ids, const int32_t* instance_ids);

  /// Adds one annotation (a visible or an amodal mask). The mask's size must be the image's; an
  /// empty mask or an unknown category is skipped and counted. Throws std::invalid_argument for an
  /// unknown image id or a mask of another size.
  void addAnnotation(int image_id, const CocoObjectMask& object);

  size_t images() const { return images_.size(); }
  size_t annotations() const { return annotations_.size(); }
  /// Objects left out: class not among the categories, or an empty mask.
  size_t skipped_objects() const { return skipped_; }

  /// The whole file: {"info", "licenses", "images", "categories", "annotations"}; each annotation
  /// with id, image_id, category_id, segmentation {"size": [h, w], "counts": RLE string}, area,
  /// bbox [x, y, w, h], iscrowd 0, track_id.
  std::string json() const;
  /// Writes json() to `path` (a temporary file renamed). Throws std::runtime_error naming the file.
  void write(const std::string& path) const;

 private:
  struct Image {
    std::string file_name, sequence;
    uint32_t width = 0, height = 0;
    int64_t frame_index = 0;
  };
  struct Annotation {
    int image_id = 0;
    int category_id = 0;
    int64_t track_id = 0;
    std::string counts;
    uint64_t area = 0;
    std::vector<uint32_t> box;
    uint32_t height = 0, width = 0;
  };
  const Image& image(int image_id) const;

  std::vector<CocoCategory> categories_;
  std::vector<Image> images_;
  std::vector<Annotation> annotations_;
  size_t skipped_ = 0;
};

}  // namespace viper::dataset
