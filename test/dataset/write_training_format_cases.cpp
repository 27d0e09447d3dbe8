// Writes the training-format fixture's frames (training_format_cases.h) with the package's writers,
// for scripts/training_formats_reference.sh to run the formats' reference code on:
//   OUT/cityscapes/gtFine/train/viper/viper_000001_00000F_gtFine_*.png (F = 0, 1)
//   OUT/coco/instances.json          visible masks of both frames
//   OUT/coco/instances_amodal.json   the amodal rectangles of both frames
//   OUT/kitti/flow/00000F_10.png, OUT/kitti/depth/00000F.png  KITTI's 16-bit flow and depth
// Usage: write_training_format_cases OUT_DIR
#include "training_format_cases.h"

#include "viper/dataset/cityscapes.h"
#include "viper/dataset/kitti_images.h"

#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_training_format_cases OUT_DIR\n";
    return 2;
  }
  const std::string out = argv[1];
  try {
    for (int f = 0; f < 2; ++f) {
      const auto frame = viper_dataset_test::trainingFormatFrame(f);
      constexpr uint32_t W = viper_dataset_test::TrainingFormatFrame::kWidth;
      constexpr uint32_t H = viper_dataset_test::TrainingFormatFrame::kHeight;
      viper::dataset::CityscapesFrameName name;
      name.sequence = 1;
      name.frame = static_cast<uint32_t>(f);
      viper::dataset::writeCityscapesFrame(
          out + "/cityscapes", name,
          viper::dataset::cityscapesGroundTruth(frame.classes.data(), frame.instances.data(), W, H), nullptr);
    }
    std::filesystem::create_directories(out + "/kitti/flow");
    std::filesystem::create_directories(out + "/kitti/depth");
    for (int f = 0; f < 2; ++f) {
      const auto frame = viper_dataset_test::trainingFormatFrame(f);
      const auto flow = viper_dataset_test::trainingFormatFlow(frame);
      viper::dataset::writeKittiFlow(out + "/kitti/flow/00000" + std::to_string(f) + "_10.png", flow);
      viper::dataset::writeKittiDepth(out + "/kitti/depth/00000" + std::to_string(f) + ".png", frame.depth_m.data(),
                                      flow.width, flow.height);
    }
    std::filesystem::create_directories(out + "/coco");
    const auto [visible, amodal] = viper_dataset_test::trainingFormatCoco();
    visible.write(out + "/coco/instances.json");
    amodal.write(out + "/coco/instances_amodal.json");
  } catch (const std::exception& e) {
    std::cerr << "write_training_format_cases: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
