#include "viper/dataset/cityscapes.h"

#include "deflate_writers.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <utility>

namespace viper::dataset {
namespace {

constexpr int kInstancesPerLabel = 1000;  // Cityscapes' instance ids are label * 1000 + k

}  // namespace

const std::vector<CityscapesLabel>& cityscapesLabels() {
  // cityscapesScripts helpers/labels.py: id, name, trainId, hasInstances, ignoreInEval, color.
  static const std::vector<CityscapesLabel> labels = {
      {0, "unlabeled", 255, false, true, {{0, 0, 0}}},
      {1, "ego vehicle", 255, false, true, {{0, 0, 0}}},
      {2, "rectification border", 255, false, true, {{0, 0, 0}}},
      {3, "out of roi", 255, false, true, {{0, 0, 0}}},
      {4, "static", 255, false, true, {{0, 0, 0}}},
      {5, "dynamic", 255, false, true, {{111, 74, 0}}},
      {6, "ground", 255, false, true, {{81, 0, 81}}},
      {7, "road", 0, false, false, {{128, 64, 128}}},
      {8, "sidewalk", 1, false, false, {{244, 35, 232}}},
      {9, "parking", 255, false, true, {{250, 170, 160}}},
      {10, "rail track", 255, false, true, {{230, 150, 140}}},
      {11, "building", 2, false, false, {{70, 70, 70}}},
      {12, "wall", 3, false, false, {{102, 102, 156}}},
      {13, "fence", 4, false, false, {{190, 153, 153}}},
      {14, "guard rail", 255, false, true, {{180, 165, 180}}},
      {15, "bridge", 255, false, true, {{150, 100, 100}}},
      {16, "tunnel", 255, false, true, {{150, 120, 90}}},
      {17, "pole", 5, false, false, {{153, 153, 153}}},
      {18, "polegroup", 255, false, true, {{153, 153, 153}}},
      {19, "traffic light", 6, false, false, {{250, 170, 30}}},
      {20, "traffic sign", 7, false, false, {{220, 220, 0}}},
      {21, "vegetation", 8, false, false, {{107, 142, 35}}},
      {22, "terrain", 9, false, false, {{152, 251, 152}}},
      {23, "sky", 10, false, false, {{70, 130, 180}}},
      {24, "person", 11, true, false, {{220, 20, 60}}},
      {25, "rider", 12, true, false, {{255, 0, 0}}},
      {26, "car", 13, true, false, {{0, 0, 142}}},
      {27, "truck", 14, true, false, {{0, 0, 70}}},
      {28, "bus", 15, true, false, {{0, 60, 100}}},
      {29, "caravan", 255, true, true, {{0, 0, 90}}},
      {30, "trailer", 255, true, true, {{0, 0, 110}}},
      {31, "train", 16, true, false, {{0, 80, 100}}},
      {32, "motorcycle", 17, true, false, {{0, 0, 230}}},
      {33, "bicycle", 18, true, false, {{119, 11, 32}}},
  };
  return labels;
}

uint8_t cityscapesLabelOfViperClass(int viper_class_id) {
  // VIPER class id (config/viper_classes.csv) -> Cityscapes label id; why each: docs/training_formats.md.
  static constexpr uint8_t kMap[32] = {
      0,   // unlabeled -> unlabeled
      0,   // ambiguous -> unlabeled
      23,  // sky
      7,   // road
      8,   // sidewalk
      10,  // railtrack -> rail track
      22,  // terrain
      21,  // tree -> vegetation
      21,  // vegetation
      11,  // building
      17,  // infrastructure (tall and thin: poles, lamps) -> pole
      13,  // fence
      4,   // billboard -> static
      19,  // trafficlight -> traffic light
      20,  // trafficsign -> traffic sign
      5,   // mobilebarrier -> dynamic
      4,   // firehydrant -> static
      5,   // chair -> dynamic
      5,   // trash -> dynamic
      4,   // trashcan -> static
      24,  // person
      5,   // animal -> dynamic
      33,  // bicycle
      32,  // motorcycle
      26,  // car
      26,  // van -> car
      28,  // bus
      27,  // truck
      30,  // trailer
      31,  // train
      5,   // plane -> dynamic
      5,   // boat -> dynamic
  };
  if (viper_class_id < 0 || viper_class_id >= 32) return 0;
  return kMap[viper_class_id];
}

CityscapesGroundTruth cityscapesGroundTruth(const uint8_t* viper_class_ids, const int32_t* instance_ids,
                                            uint32_t width, uint32_t height) {
  const size_t n = static_cast<size_t>(width) * height;
  if (n > 0 && (viper_class_ids == nullptr || instance_ids == nullptr))
    throw std::invalid_argument("cityscapesGroundTruth: no class or instance ids for a non-empty image");
  const auto& labels = cityscapesLabels();
  std::array<uint8_t, 256> label_of{};
  for (int c = 0; c < 256; ++c) label_of[c] = cityscapesLabelOfViperClass(c);

  // k per (label, VIPER instance id), in the order of the instance ids.
  std::map<std::pair<uint8_t, int32_t>, int> index;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t label = label_of[viper_class_ids[i]];
    if (labels[label].has_instances && instance_ids[i] != 0) index.emplace(std::make_pair(label, instance_ids[i]), 0);
  }
  CityscapesGroundTruth gt;
  std::array<int, 256> count{};
  for (auto& [key, k] : index) {
    k = count[key.first]++;
    if (k >= kInstancesPerLabel) ++gt.instances_over_limit;
  }

  gt.width = width;
  gt.height = height;
  gt.label_ids.resize(n);
  gt.train_ids.resize(n);
  gt.instance_ids.resize(n);
  gt.color_rgba.resize(4 * n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t label = label_of[viper_class_ids[i]];
    const CityscapesLabel& l = labels[label];
    gt.label_ids[i] = label;
    gt.train_ids[i] = static_cast<uint8_t>(l.train_id);
    uint16_t id = label;
    if (l.has_instances) {
      int k = kInstancesPerLabel;
      if (instance_ids[i] != 0) k = index.at({label, instance_ids[i]});
      if (k < kInstancesPerLabel)
        id = static_cast<uint16_t>(label * kInstancesPerLabel + k);
      else
        ++gt.group_pixels;
    }
    gt.instance_ids[i] = id;
    std::copy(l.color.begin(), l.color.end(), gt.color_rgba.begin() + 4 * i);
    gt.color_rgba[4 * i + 3] = 255;
  }
  return gt;
}

std::string CityscapesFrameName::stem() const {
  if (city.empty() || city.find_first_of("_/") != std::string::npos)
    throw std::invalid_argument("Cityscapes city name '" + city + "' must be non-empty, without '_' or '/'");
  if (sequence > 999999 || frame > 999999)
    throw std::invalid_argument("Cityscapes sequence and frame numbers have 6 digits, got " +
                                std::to_string(sequence) + " and " + std::to_string(frame));
  char numbers[32];
  std::snprintf(numbers, sizeof numbers, "_%06u_%06u", sequence, frame);
  return city + numbers;
}

void writeCityscapesFrame(const std::string& root, const CityscapesFrameName& name,
                          const CityscapesGroundTruth& gt, const ImageView8* left_rgb,
                          const ImageWriteOptions& options) {
  const size_t n = static_cast<size_t>(gt.width) * gt.height;
  if (n == 0 || gt.label_ids.size() != n || gt.train_ids.size() != n || gt.instance_ids.size() != n ||
      gt.color_rgba.size() != 4 * n)
    throw std::invalid_argument("Cityscapes ground truth of " + std::to_string(gt.width) + "x" +
                                std::to_string(gt.height) + " px has images of other sizes");
  if (left_rgb != nullptr && (left_rgb->width != gt.width || left_rgb->height != gt.height))
    throw std::invalid_argument("leftImg8bit image of " + std::to_string(left_rgb->width) + "x" +
                                std::to_string(left_rgb->height) + " px for ground truth of " +
                                std::to_string(gt.width) + "x" + std::to_string(gt.height) + " px");
  if (name.split.empty() || name.split.find('/') != std::string::npos)
    throw std::invalid_argument("Cityscapes split '" + name.split + "' must be non-empty, without '/'");
  const std::string stem = name.stem();
  namespace fs = std::filesystem;
  const fs::path gt_dir = fs::path(root) / "gtFine" / name.split / name.city;
  fs::create_directories(gt_dir);
  const int level = options.png_compression_level;
  const std::string base = (gt_dir / stem).string() + "_gtFine_";
  using detail::PngColor;
  detail::writeFileAtomically(base + "labelIds.png",
                              detail::pngBytes(gt.label_ids.data(), gt.width, gt.height, PngColor::kGray, {}, level),
                              "PNG", options.digests);
  detail::writeFileAtomically(base + "labelTrainIds.png",
                              detail::pngBytes(gt.train_ids.data(), gt.width, gt.height, PngColor::kGray, {}, level),
                              "PNG", options.digests);
  detail::writeFileAtomically(base + "instanceIds.png",
                              detail::pngBytes16(gt.instance_ids.data(), gt.width, gt.height, PngColor::kGray, level),
                              "PNG", options.digests);
  detail::writeFileAtomically(base + "color.png",
                              detail::pngBytes(gt.color_rgba.data(), gt.width, gt.height, PngColor::kRgba, {}, level),
                              "PNG", options.digests);
  if (left_rgb != nullptr) {
    const fs::path img_dir = fs::path(root) / "leftImg8bit" / name.split / name.city;
    fs::create_directories(img_dir);
    writeViperColorImage((img_dir / (stem + "_leftImg8bit.png")).string(), *left_rgb, options);
  }
}

}  // namespace viper::dataset
