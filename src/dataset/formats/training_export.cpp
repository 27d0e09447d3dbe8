#include "viper/dataset/training_export.h"

#include "viper/dataset/cityscapes.h"
#include "viper/dataset/kitti_images.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <utility>

namespace viper::dataset {
namespace {

std::string digits(uint32_t value, int width) {
  char s[16];
  std::snprintf(s, sizeof s, "%0*u", width, value);
  return s;
}

}  // namespace

TrainingExport::TrainingExport(TrainingExportOptions options) : options_(std::move(options)) {
  if (options_.split.empty() || options_.split.find('/') != std::string::npos)
    throw std::invalid_argument("split '" + options_.split + "' must be non-empty, without '/'");
  CityscapesFrameName name;
  name.city = options_.city;
  name.sequence = options_.sequence;
  name.stem();  // throws for a bad city or sequence
  if (options_.coco) {
    coco_.emplace(options_.categories);
    coco_amodal_.emplace(options_.categories);
  }
}

void TrainingExport::addFrame(const TrainingFrame& f) {
  namespace fs = std::filesystem;
  const fs::path root(options_.root);
  const bool ids = f.class_ids != nullptr && f.instance_ids != nullptr;
  if (f.rgb != nullptr && ids && (f.rgb->width != f.width || f.rgb->height != f.height))
    throw std::invalid_argument("frame " + std::to_string(f.frame) + ": image of " + std::to_string(f.rgb->width) +
                                "x" + std::to_string(f.rgb->height) + " px, ids of " + std::to_string(f.width) +
                                "x" + std::to_string(f.height) + " px");
  if (options_.cityscapes && ids) {
    CityscapesFrameName name;
    name.split = options_.split;
    name.city = options_.city;
    name.sequence = options_.sequence;
    name.frame = f.frame;
    const CityscapesGroundTruth gt = cityscapesGroundTruth(f.class_ids, f.instance_ids, f.width, f.height);
    writeCityscapesFrame((root / "cityscapes").string(), name, gt, f.rgb, options_.images);
    ++stats_.cityscapes_frames;
    stats_.cityscapes_group_pixels += gt.group_pixels;
    stats_.cityscapes_instances_over_limit += gt.instances_over_limit;
  }
  if (coco_ && ids) {
    const std::string file = digits(options_.sequence, 6) + "_" + digits(f.frame, 6) + ".png";
    if (f.rgb != nullptr) {
      const fs::path dir = root / "coco" / options_.split;
      fs::create_directories(dir);
      writeViperColorImage((dir / file).string(), *f.rgb, options_.images);
    }
    const size_t before = coco_->annotations();
    coco_->addVisibleInstances(coco_->addImage(file, f.width, f.height, digits(options_.sequence, 6), f.frame),
                               f.class_ids, f.instance_ids);
    ++stats_.coco_images;
    stats_.coco_annotations += coco_->annotations() - before;
    stats_.coco_skipped_objects = coco_->skipped_objects();
  }
  if (coco_amodal_ && f.amodal != nullptr && !f.amodal->empty()) {
    if (f.width == 0 || f.height == 0)
      throw std::invalid_argument("frame " + std::to_string(f.frame) + ": amodal masks without the image's size");
    const std::string file = digits(options_.sequence, 6) + "_" + digits(f.frame, 6) + ".png";
    const int image = coco_amodal_->addImage(file, f.width, f.height, digits(options_.sequence, 6), f.frame);
    const size_t before = coco_amodal_->annotations();
    for (const TrainingAmodalMask& m : *f.amodal)
      coco_amodal_->addAnnotation(image, {m.class_id, m.track_id,
                                          cocoRleOfBoxMask(f.width, f.height, m.box_x, m.box_y, m.box_width,
                                                           m.box_height, m.mask)});
    stats_.coco_amodal_annotations += coco_amodal_->annotations() - before;
  }
  if (!options_.kitti) return;
  const fs::path kitti = root / "kitti" / options_.split / digits(options_.sequence, 6);
  if (f.flow != nullptr) {
    fs::create_directories(kitti / "flow_occ");
    const KittiEncodeStats s = writeKittiFlow((kitti / "flow_occ" / (digits(f.frame, 6) + "_10.png")).string(),
                                              *f.flow, options_.images);
    ++stats_.kitti_flow;
    stats_.kitti_flow_out_of_range += s.out_of_range;
  }
  if (f.depth_m != nullptr) {
    const fs::path dir = kitti / "proj_depth" / "groundtruth" / "image_02";
    fs::create_directories(dir);
    const KittiEncodeStats s =
        writeKittiDepth((dir / (digits(f.frame, 10) + ".png")).string(), f.depth_m, f.width, f.height, options_.images);
    ++stats_.kitti_depth;
    stats_.kitti_depth_out_of_range += s.out_of_range;
  }
}

void TrainingExport::finish() {
  const std::filesystem::path dir = std::filesystem::path(options_.root) / "coco" / "annotations";
  const std::string name = options_.split + "_" + digits(options_.sequence, 6) + ".json";
  if (coco_ && coco_->images() > 0) {
    std::filesystem::create_directories(dir);
    coco_->write((dir / ("instances_" + name)).string());
  }
  if (coco_amodal_ && coco_amodal_->images() > 0) {
    std::filesystem::create_directories(dir);
    coco_amodal_->write((dir / ("instances_amodal_" + name)).string());
  }
}

}  // namespace viper::dataset
