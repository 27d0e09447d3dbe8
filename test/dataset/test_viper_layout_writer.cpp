// The layout writer on core types (viper_layout_writer.h), as `generate` hands it the ground-truth
// pipeline's results: images read where they are and held by their owner until written (writer
// threads), inst ready-made, bb from the boxes step's boxes with the objects' 2D boxes, a camera row
// from the frame's camera; and parts that never find their partner reported at the flush. Messages
// through ViperExporter: test/ros/test_viper_layout_conversions.cpp.
#include "viper/dataset/viper_layout_writer.h"

#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"

#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <vector>

namespace viper {
namespace {

namespace fs = std::filesystem;

ViperExportOptions options(const std::string& root, unsigned threads) {
  ViperExportOptions o;
  o.root = root;
  o.writer_threads = threads;
  o.inputs.instances_viper = true;
  return o;
}

TEST(ViperLayoutWriter, WritesAFrameFromCoreTypesHoldingItsPixelsUntilWritten) {
  const std::string root = test::tempDir("viper_layout_writer_");
  ViperLayoutWriter w(options(root, 2));
  const uint32_t W = 4, H = 2;
  auto rgb = std::make_shared<std::vector<uint8_t>>(3 * W * H, 200);
  auto cls = std::make_shared<std::vector<uint8_t>>(W * H, 24);
  auto inst = std::make_shared<std::vector<uint8_t>>(3 * W * H, 0);
  auto uv = std::make_shared<std::vector<float>>(2 * W * H, 0.5f);
  EXPECT_EQ(w.addColor(0, dataset::ImageView8(rgb->data(), W, H, 3), rgb), "");
  EXPECT_EQ(w.addSemantic(0, dataset::ImageView8(cls->data(), W, H, 1), cls), "");
  EXPECT_EQ(w.addInstancesViper(0, dataset::ImageView8(inst->data(), W, H, 3), inst), "");
  EXPECT_EQ(w.addFlow(0, uv->data(), W, H, uv, false), "");

  TrackedObject car;
  car.track_id = 7, car.object.class_id = 24, car.object.pixel_count = 3;
  car.object.x_min = 1, car.object.y_min = 0, car.object.x_max = 3, car.object.y_max = 1;
  TrackedObject unseen = car;
  unseen.track_id = 8, unseen.object.pixel_count = 0;
  const Boxes2d boxes_2d = objectBoxes2d({car, unseen});
  ASSERT_EQ(boxes_2d.size(), 1u) << "objects without pixels have no 2D box";
  EXPECT_EQ(boxes_2d.at(7), (std::array<double, 4>{{1, 0, 3, 1}}));
  FrameBoxes boxes;
  boxes.has_optical = true;
  TrackBox b;
  b.track_id = 7, b.class_id = 24;
  b.in_optical.center = {0, 0, 10};
  b.in_optical.size = {4, 2, 1.5};
  boxes.boxes = {b};
  EXPECT_EQ(w.addObjects(0, boxes_2d), "");
  EXPECT_EQ(w.addBoxesOptical(0, viperBoxes(boxes)), "");
  FrameCamera camera;
  camera.projection(3, 2) = -1, camera.projection(3, 3) = 0;
  EXPECT_EQ(w.addCamera(0, camera), "");
  EXPECT_NE(w.addCamera(1, std::nullopt), "") << "a frame without a camera has no row";

  EXPECT_TRUE(w.finish().empty());
  EXPECT_EQ(rgb.use_count(), 1) << "written: the writer let go of the pixels";
  EXPECT_EQ(uv.use_count(), 1);
  const ViperExportStats s = w.stats();
  EXPECT_EQ(s.img, 1u);
  EXPECT_EQ(s.cls, 1u);
  EXPECT_EQ(s.inst, 1u);
  EXPECT_EQ(s.flow, 1u);
  EXPECT_EQ(s.bb, 1u);
  EXPECT_EQ(s.camera_rows, 1u);
  EXPECT_EQ(s.skipped, 1u);
  const auto frame_file = [&](const char* modality, const char* ext) {
    return dataset::viperFramePath(root, "train", modality, "001", 0, ext);
  };
  EXPECT_EQ(dataset::readViperColorImage(frame_file("img", "png")).data, *rgb);
  EXPECT_EQ(dataset::readViperClassImage(frame_file("cls", "png")).data, *cls);
  EXPECT_EQ(dataset::readViperFlow(frame_file("flow", "npz")).uv, *uv);
  std::vector<std::string> problems;
  const auto rows = dataset::readViperBoxesCsv(frame_file("bb", "csv"), problems);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].instance_id, 7);
  EXPECT_EQ(rows[0].class_id, 24);
  EXPECT_EQ(rows[0].box_2d, (std::array<double, 4>{{1, 0, 3, 1}}));
  EXPECT_DOUBLE_EQ(rows[0].box_3d[3], 2.0);
  EXPECT_TRUE(fs::is_regular_file(dataset::viperCameraPath(root, "train", "001")));
}

TEST(ViperLayoutWriter, PixelsWithoutOwnerAreCopiedAndPartsWithoutPartnerAreReported) {
  const std::string root = test::tempDir("viper_layout_writer_");
  ViperExportOptions o = options(root, 1);
  o.inputs.instances_viper = false;  // inst from class ids + instance ids
  ViperLayoutWriter w(o);
  std::vector<uint8_t> cls(4, 26);
  std::vector<int32_t> ids = {0, 300, 300, 0};
  EXPECT_EQ(w.addSemantic(0, dataset::ImageView8(cls.data(), 2, 2, 1), nullptr), "");
  cls.assign(4, 0);  // the writer copied them
  EXPECT_EQ(w.addInstanceIds(0, ids.data(), 2, 2, nullptr), "");
  // Class ids whose instance ids never come wait for them, held by their owner, until the flush.
  auto waiting = std::make_shared<std::vector<uint8_t>>(4, 3);
  EXPECT_EQ(w.addSemantic(1, dataset::ImageView8(waiting->data(), 2, 2, 1), waiting), "");
  EXPECT_GT(waiting.use_count(), 1);
  const std::vector<std::string> notes = w.finish();
  EXPECT_EQ(waiting.use_count(), 1);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("frame 1: semantic without instance ids"), std::string::npos) << notes[0];
  const dataset::Image8 inst = dataset::readViperInstanceImage(dataset::viperFramePath(root, "train", "inst", "001", 0, "png"));
  EXPECT_EQ(inst.data[3], 26);
  EXPECT_EQ(256 * inst.data[4] + inst.data[5], 300);
  EXPECT_EQ(dataset::readViperClassImage(dataset::viperFramePath(root, "train", "cls", "001", 0, "png")).data[0], 26);
}

}  // namespace
}  // namespace viper
