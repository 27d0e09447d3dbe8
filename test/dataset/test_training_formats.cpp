// The training formats' writers against what the formats' reference code read from their files
// (test/dataset/data/training_formats, made by scripts/training_formats_reference.sh from the frames
// of training_format_cases.h): the files written here, decoded by OpenCV, hold the values the
// reference's readers got, and the reference scored those files as perfect.
#include "dataset_test_util.h"
#include "training_format_cases.h"

#include "viper/dataset/cityscapes.h"
#include "viper/dataset/file_digests.h"
#include "viper/dataset/kitti_images.h"
#include "viper/dataset/kitti_labels.h"
#include "viper/dataset/training_export.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using viper_dataset_test::TrainingFormatFrame;
using viper_dataset_test::trainingFormatFrame;
namespace ds = viper::dataset;

const std::string kFixtures = "test/dataset/data/training_formats/";

struct FileValues {
  std::string mode, shape, sha256;
};

struct RleValues {
  std::string counts, area, box;
};

struct Fixture {
  std::map<std::string, FileValues> files;
  std::map<std::string, RleValues> rles;
  std::map<std::string, std::string> scores;
};

Fixture readFixture(const std::string& name) {
  std::ifstream in(kFixtures + name);
  EXPECT_TRUE(in.good()) << kFixtures + name;
  Fixture fixture;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string kind, key;
    fields >> kind >> key;
    if (kind == "file") {
      FileValues v;
      fields >> v.mode >> v.shape >> v.sha256;
      fixture.files[key] = v;
    } else if (kind == "rle") {
      RleValues v;
      fields >> v.counts >> v.area >> v.box;
      fixture.rles[key] = v;
    } else if (kind == "score") {
      fields >> fixture.scores[key];
    } else {
      ADD_FAILURE() << name << ": unknown line '" << line << "'";
    }
  }
  return fixture;
}

// The values of a PNG as the reference's reader gives them (channels red first), as
// "HEIGHTxWIDTHxCHANNELS" and the SHA-256 of the values as little-endian int32.
FileValues decoded(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(image.empty()) << path;
  const int channels = image.channels();
  std::vector<int32_t> values;
  values.reserve(image.total() * channels);
  static const int kRgbOrder[4] = {2, 1, 0, 3};  // OpenCV's BGR(A) -> RGB(A)
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      for (int c = 0; c < channels; ++c) {
        const int k = channels >= 3 ? kRgbOrder[c] : c;
        values.push_back(image.depth() == CV_16U ? image.ptr<uint16_t>(y)[x * channels + k]
                                                 : image.ptr<uint8_t>(y)[x * channels + k]);
      }
  FileValues v;
  v.mode = image.depth() == CV_16U ? "16bit" : "8bit";
  v.shape = std::to_string(image.rows) + "x" + std::to_string(image.cols) + "x" + std::to_string(channels);
  v.sha256 = ds::sha256Hex(values.data(), values.size() * sizeof(int32_t));  // little-endian host
  return v;
}

TEST(Cityscapes, WrittenFilesHoldWhatCityscapesScriptsRead) {
  const Fixture fixture = readFixture("cityscapes.txt");
  ASSERT_EQ(fixture.files.size(), 8u);
  viper_dataset_test::TempDir dir;
  for (int f = 0; f < 2; ++f) {
    const TrainingFormatFrame frame = trainingFormatFrame(f);
    ds::CityscapesFrameName name;
    name.sequence = 1;
    name.frame = static_cast<uint32_t>(f);
    ds::writeCityscapesFrame(dir.path().string() + "/cityscapes", name,
                             ds::cityscapesGroundTruth(frame.classes.data(), frame.instances.data(),
                                                       TrainingFormatFrame::kWidth, TrainingFormatFrame::kHeight),
                             nullptr);
  }
  // PIL's modes: L (8-bit gray), I (16-bit gray read as int32), RGBA.
  const std::map<std::string, std::string> depth_of_mode = {{"L", "8bit"}, {"I", "16bit"}, {"RGBA", "8bit"}};
  for (const auto& [file, expected] : fixture.files) {
    SCOPED_TRACE(file);
    const FileValues got = decoded(dir.path().string() + "/cityscapes/gtFine/" + file);
    EXPECT_EQ(got.mode, depth_of_mode.at(expected.mode));
    EXPECT_EQ(got.shape, expected.shape);
    EXPECT_EQ(got.sha256, expected.sha256);
  }
  // What cityscapesScripts scored these files as, predicting themselves.
  for (const char* score : {"pixel_averageScoreClasses", "pixel_averageScoreInstClasses", "instance_allAp",
                            "instance_allAp50", "instance_ap_car", "instance_ap_person", "instance_ap_truck"})
    EXPECT_EQ(fixture.scores.count(score) ? fixture.scores.at(score) : "", "1.0") << score;
}

// The annotations of a COCO file as written: counts (JSON unescaped), area, "x,y,w,h", in order.
std::vector<RleValues> cocoAnnotations(const std::string& json) {
  std::vector<RleValues> out;
  const std::string counts_key = "\"counts\": \"", area_key = "\"area\": ", box_key = "\"bbox\": [";
  for (size_t at = json.find(counts_key); at != std::string::npos; at = json.find(counts_key, at)) {
    RleValues v;
    for (at += counts_key.size(); json[at] != '"'; ++at) {
      if (json[at] == '\\') ++at;
      v.counts += json[at];
    }
    at = json.find(area_key, at) + area_key.size();
    v.area = json.substr(at, json.find(',', at) - at);
    at = json.find(box_key, at) + box_key.size();
    v.box = json.substr(at, json.find(']', at) - at);
    v.box.erase(std::remove(v.box.begin(), v.box.end(), ' '), v.box.end());
    out.push_back(v);
  }
  return out;
}

// A mask from its counts (column-major runs), row-major 0/1 values as int32.
std::vector<int32_t> decodeRle(const std::string& counts, uint32_t width, uint32_t height) {
  // Inverse of cocoRleString (maskApi's rleFrString).
  std::vector<int64_t> runs;
  for (size_t p = 0; p < counts.size();) {
    int64_t x = 0;
    int k = 0;
    bool more = true;
    while (more) {
      const int64_t c = counts[p] - 48;
      x |= (c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      if (!more && (c & 0x10)) x |= -1LL << (5 * k);
    }
    if (runs.size() > 2) x += runs[runs.size() - 2];
    runs.push_back(x);
  }
  std::vector<int32_t> mask(static_cast<size_t>(width) * height);
  uint64_t at = 0;
  for (size_t j = 0; j < runs.size(); ++j) {
    for (int64_t r = 0; r < runs[j]; ++r, ++at)
      if (j % 2 == 1) mask[(at % height) * width + at / height] = 1;
  }
  EXPECT_EQ(at, static_cast<uint64_t>(width) * height);
  return mask;
}

TEST(Coco, AnnotationsAreWhatTheCocoApiEncodesAndDecodes) {
  const Fixture fixture = readFixture("coco.txt");
  const auto [visible, amodal] = viper_dataset_test::trainingFormatCoco();
  const std::map<std::string, std::string> files = {{"instances.json", visible.json()},
                                                    {"instances_amodal.json", amodal.json()}};
  size_t checked = 0;
  for (const auto& [file, json] : files) {
    const std::vector<RleValues> annotations = cocoAnnotations(json);
    for (size_t i = 0; i < annotations.size(); ++i) {
      const std::string key = file + ":" + std::to_string(i + 1);
      SCOPED_TRACE(key);
      ASSERT_EQ(fixture.rles.count(key), 1u);
      // pycocotools' encoding of the mask it decoded from our file is our string, area and box.
      EXPECT_EQ(annotations[i].counts, fixture.rles.at(key).counts);
      EXPECT_EQ(annotations[i].area, fixture.rles.at(key).area);
      EXPECT_EQ(annotations[i].box, fixture.rles.at(key).box);
      // And the mask it decoded is ours.
      const auto mask = decodeRle(annotations[i].counts, TrainingFormatFrame::kWidth, TrainingFormatFrame::kHeight);
      EXPECT_EQ(ds::sha256Hex(mask.data(), mask.size() * sizeof(int32_t)), fixture.files.at(key).sha256);
      ++checked;
    }
  }
  EXPECT_EQ(checked, fixture.rles.size());
  EXPECT_EQ(checked, 16u);
  // The visible masks of the first frame are the instance ids' pixels, as the COCO API decoded them.
  const TrainingFormatFrame frame = trainingFormatFrame(0);
  for (const auto& [key, id] : std::vector<std::pair<std::string, int32_t>>{
           {"instances.json:1", 3}, {"instances.json:2", 7}, {"instances.json:3", 12}, {"instances.json:4", 40000}}) {
    std::vector<int32_t> mask(frame.instances.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = frame.instances[i] == id;
    EXPECT_EQ(ds::sha256Hex(mask.data(), mask.size() * sizeof(int32_t)), fixture.files.at(key).sha256) << key;
  }
  EXPECT_EQ(visible.skipped_objects(), 2u);  // the traffic sign in both frames
  for (const char* score : {"instances_segm_AP", "instances_segm_AP50", "instances_bbox_AP", "instances_amodal_segm_AP",
                            "instances_amodal_bbox_AP"})
    EXPECT_EQ(fixture.scores.count(score) ? fixture.scores.at(score) : "", "1.0") << score;
}

TEST(Coco, EdgeMasks) {
  // Empty mask: one run of 0s; a mask from the first pixel: a first run of length 0.
  const auto empty = ds::cocoRleOfBoxMask(3, 2, 0, 0, 0, 0, nullptr);
  EXPECT_EQ(empty.counts, (std::vector<uint32_t>{6}));
  EXPECT_EQ(ds::cocoRleBox(empty), (std::vector<uint32_t>{0, 0, 0, 0}));
  const uint8_t first[1] = {1};
  const auto corner = ds::cocoRleOfBoxMask(3, 2, 0, 0, 1, 1, first);
  EXPECT_EQ(corner.counts, (std::vector<uint32_t>{0, 1, 5}));
  EXPECT_EQ(ds::cocoRleString(corner), "015");
  // A box wholly outside the image gives an empty mask.
  EXPECT_EQ(ds::cocoRleOfBoxMask(3, 2, 5, 5, 1, 1, first).counts, (std::vector<uint32_t>{6}));
  ds::CocoInstancesWriter writer({{1, "a", "b"}});
  EXPECT_THROW(writer.addAnnotation(1, {1, 1, corner}), std::invalid_argument);  // no image 1 yet
  const int image = writer.addImage("x.png", 4, 2, "s", 0);
  EXPECT_THROW(writer.addAnnotation(image, {1, 1, corner}), std::invalid_argument);  // 3x2 mask, 4x2 image
}

// A KITTI PNG read as the devkits read it: flow (u, v, valid) with u = (red - 2^15) / 64 where blue
// > 0, else (0, 0, 0); depth value / 256 where non-zero, else -1. Float32 values.
std::vector<float> kittiDevkitValues(const std::string& path, bool flow) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  EXPECT_EQ(image.depth(), CV_16U) << path;
  EXPECT_EQ(image.channels(), flow ? 3 : 1) << path;
  std::vector<float> values;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      if (flow) {
        const cv::Vec3w bgr = image.at<cv::Vec3w>(y, x);
        const bool valid = bgr[0] > 0;
        values.push_back(valid ? (static_cast<float>(bgr[2]) - 32768.0f) / 64.0f : 0.0f);
        values.push_back(valid ? (static_cast<float>(bgr[1]) - 32768.0f) / 64.0f : 0.0f);
        values.push_back(valid ? 1.0f : 0.0f);
      } else {
        const uint16_t d = image.at<uint16_t>(y, x);
        values.push_back(d == 0 ? -1.0f : static_cast<float>(d) / 256.0f);
      }
    }
  return values;
}

TEST(Kitti, FlowAndDepthAreWhatTheDevkitsRead) {
  const Fixture fixture = readFixture("kitti.txt");
  ASSERT_EQ(fixture.files.size(), 4u);
  viper_dataset_test::TempDir dir;
  const std::string root = dir.path().string();
  std::filesystem::create_directories(root + "/flow");
  std::filesystem::create_directories(root + "/depth");
  constexpr uint32_t W = TrainingFormatFrame::kWidth, H = TrainingFormatFrame::kHeight;
  for (int f = 0; f < 2; ++f) {
    SCOPED_TRACE(f);
    const TrainingFormatFrame frame = trainingFormatFrame(f);
    const std::string flow_name = "flow/00000" + std::to_string(f) + "_10.png";
    const std::string depth_name = "depth/00000" + std::to_string(f) + ".png";
    const auto flow_stats = ds::writeKittiFlow(root + "/" + flow_name, viper_dataset_test::trainingFormatFlow(frame));
    const auto depth_stats = ds::writeKittiDepth(root + "/" + depth_name, frame.depth_m.data(), W, H);
    EXPECT_EQ(flow_stats.not_finite, 7u);  // the NaN corner and an inf
    EXPECT_EQ(flow_stats.out_of_range, 1u);  // 600 px
    EXPECT_EQ(std::to_string(flow_stats.valid), fixture.scores.at(flow_name + "_valid_pixels"));
    EXPECT_EQ(depth_stats.not_finite, 1503u);  // the sky
    EXPECT_EQ(depth_stats.out_of_range, 1u);   // 300 m
    EXPECT_EQ(std::to_string(depth_stats.valid), fixture.scores.at(depth_name + "_valid_pixels"));

    const std::vector<float> flow = kittiDevkitValues(root + "/" + flow_name, true);
    const std::vector<float> depth = kittiDevkitValues(root + "/" + depth_name, false);
    EXPECT_EQ(ds::sha256Hex(flow.data(), flow.size() * sizeof(float)), fixture.files.at(flow_name).sha256);
    EXPECT_EQ(ds::sha256Hex(depth.data(), depth.size() * sizeof(float)), fixture.files.at(depth_name).sha256);
    // What the devkits read is the input within half a step of the encoding, where it is valid.
    for (size_t i = 0; i < frame.depth_m.size(); ++i) {
      if (flow[3 * i + 2] > 0.5f) {
        EXPECT_NEAR(flow[3 * i], frame.flow_uv[2 * i], 1.0 / 128) << i;
        EXPECT_NEAR(flow[3 * i + 1], frame.flow_uv[2 * i + 1], 1.0 / 128) << i;
      }
      if (depth[i] >= 0) EXPECT_NEAR(depth[i], frame.depth_m[i], 1.0 / 512) << i;
    }
  }
}

TEST(Kitti, EdgeValues) {
  ds::FlowImage flow;
  flow.width = 5;
  flow.height = 1;
  // Exactly representable, the largest and smallest encodable, one past them.
  flow.uv = {1.5f, -2.25f, 511.984375f, -512.0f, 511.995f, 0.0f, -512.01f, 0.0f, 0.0f, 0.0f};
  ds::KittiEncodeStats stats;
  const auto values = ds::kittiFlowValues(flow, &stats);
  EXPECT_EQ(values, (std::vector<uint16_t>{32864, 32624, 1, 65535, 0, 1, 0, 0, 0, 0, 0, 0, 32768, 32768, 1}));
  EXPECT_EQ(stats.valid, 3u);
  EXPECT_EQ(stats.out_of_range, 2u);
  const float depth[5] = {0.001f, 0.0f, -1.0f, 255.99f, 256.0f};
  const auto d = ds::kittiDepthValues(depth, 5, 1, &stats);
  EXPECT_EQ(d, (std::vector<uint16_t>{1, 0, 0, 65533, 0}));
  EXPECT_EQ(stats.valid, 2u);
  EXPECT_EQ(stats.out_of_range, 3u);
}

TEST(KittiLabels, BoxesInKittisCameraConventions) {
  // A car 10 m ahead, 2 m right, its long axis (object x, 4 m) along the camera's x, its up axis
  // (object y) along the camera's -y: rotation_y 0, location at its bottom (+y by half its height).
  const Eigen::Quaterniond upright(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));  // object y -> camera -y
  ds::KittiObject o = ds::kittiObjectOfBox({2, 0.5, 10}, upright, {4, 1.5, 1.8});
  EXPECT_DOUBLE_EQ(o.height, 1.5);
  EXPECT_DOUBLE_EQ(o.length, 4);
  EXPECT_DOUBLE_EQ(o.width, 1.8);
  EXPECT_TRUE(o.location.isApprox(Eigen::Vector3d(2, 1.25, 10)));
  EXPECT_NEAR(o.rotation_y, 0, 1e-12);
  EXPECT_NEAR(o.alpha, -std::atan2(2, 10), 1e-12);
  // Turned 90 degrees about the camera's Y so that its long axis points at the camera's -z (towards
  // it): KITTI's rotation_y is then +pi/2 (x axis turned into -z).
  const Eigen::Quaterniond turned = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()) * upright;
  o = ds::kittiObjectOfBox({0, 0, 20}, turned, {4, 1.5, 1.8});
  EXPECT_NEAR(o.rotation_y, M_PI / 2, 1e-12);
  EXPECT_NEAR(o.alpha, M_PI / 2, 1e-12);  // straight ahead: alpha = rotation_y
  o.type = ds::kittiTypeOfViperClass(24);
  o.truncated = 0.125;
  o.occluded = 1;
  o.box = {{100.25, 50, 200, 120.5}};
  EXPECT_EQ(ds::kittiLabelLine(o), "Car 0.12 1 1.57 100.25 50.00 200.00 120.50 1.50 1.80 4.00 0.00 0.75 20.00 1.57");
  EXPECT_EQ(ds::kittiTrackingLine(7, 12, o).substr(0, 9), "7 12 Car ");
  EXPECT_EQ(ds::kittiTypeOfViperClass(25), "Van");
  EXPECT_EQ(ds::kittiTypeOfViperClass(20), "Pedestrian");
  EXPECT_EQ(ds::kittiTypeOfViperClass(22), "Cyclist");
  EXPECT_EQ(ds::kittiTypeOfViperClass(2), "DontCare");
}

TEST(KittiLabels, CalibHasEveryMatrixKittiReads) {
  Eigen::Matrix<double, 3, 4> P;
  P << 721.5377, 0, 609.5593, 0, 0, 721.5377, 172.854, 0, 0, 0, 1, 0;
  const std::string calib = ds::kittiCalibText(P);
  EXPECT_NE(calib.find("P2: 7.215377000000e+02 0.000000000000e+00 6.095593000000e+02 0.000000000000e+00 "
                       "0.000000000000e+00 7.215377000000e+02 1.728540000000e+02 0.000000000000e+00 "
                       "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00\n"),
            std::string::npos)
      << calib;
  EXPECT_EQ(calib.rfind("P0: ", 0), 0u);
  for (const char* name : {"P1: ", "P3: ", "R0_rect: ", "Tr_velo_to_cam: ", "Tr_imu_to_velo: "})
    EXPECT_NE(calib.find(std::string("\n") + name), std::string::npos) << name;
  EXPECT_EQ(std::count(calib.begin(), calib.end(), '\n'), 7);
}

TEST(TrainingExport, WritesEveryFormatOfAFrameAndTheAmodalMasks) {
  viper_dataset_test::TempDir dir;
  ds::TrainingExportOptions options;
  options.root = dir.path().string();
  for (const auto& [id, name] : viper_dataset_test::trainingFormatCategories()) options.categories.push_back({id, name, "viper"});
  ds::TrainingExport exporter(options);
  const TrainingFormatFrame frame = trainingFormatFrame(0);
  const auto flow = viper_dataset_test::trainingFormatFlow(frame);
  // The fixture's amodal rectangles, as the amodal step gives them (box and cropped mask).
  std::vector<std::vector<uint8_t>> masks;
  std::vector<ds::TrainingAmodalMask> amodal;
  for (const auto& r : viper_dataset_test::trainingFormatAmodal(0)) {
    masks.emplace_back(static_cast<size_t>(r.width) * r.height, 1);
    amodal.push_back({r.instance_id, r.class_id, r.x, r.y, r.width, r.height, masks.back().data()});
  }
  ds::TrainingFrame f;
  f.frame = 0;
  f.class_ids = frame.classes.data();
  f.instance_ids = frame.instances.data();
  f.width = TrainingFormatFrame::kWidth;
  f.height = TrainingFormatFrame::kHeight;
  f.flow = &flow;
  f.depth_m = frame.depth_m.data();
  f.amodal = &amodal;
  exporter.addFrame(f);
  exporter.finish();
  const auto& s = exporter.stats();
  EXPECT_EQ(s.cityscapes_frames, 1u);
  EXPECT_EQ(s.coco_annotations, 4u);
  EXPECT_EQ(s.coco_amodal_annotations, 3u);
  EXPECT_EQ(s.kitti_flow, 1u);
  EXPECT_EQ(s.kitti_depth, 1u);
  const std::string root = options.root;
  for (const char* file : {"/cityscapes/gtFine/train/viper/viper_000001_000000_gtFine_instanceIds.png",
                           "/coco/annotations/instances_train_000001.json",
                           "/coco/annotations/instances_amodal_train_000001.json",
                           "/kitti/train/000001/flow_occ/000000_10.png",
                           "/kitti/train/000001/proj_depth/groundtruth/image_02/0000000000.png"})
    EXPECT_TRUE(std::filesystem::is_regular_file(root + file)) << file;
  // The amodal file's masks are those the COCO API read in the fixture (instances_amodal.json's first image).
  const Fixture fixture = readFixture("coco.txt");
  const std::vector<uint8_t> bytes =
      viper_dataset_test::readBytes(root + "/coco/annotations/instances_amodal_train_000001.json");
  const auto written = cocoAnnotations(std::string(bytes.begin(), bytes.end()));
  ASSERT_EQ(written.size(), 3u);
  for (size_t i = 0; i < written.size(); ++i)
    EXPECT_EQ(written[i].counts, fixture.rles.at("instances_amodal.json:" + std::to_string(i + 1)).counts) << i;
}

TEST(Cityscapes, EncodesLabelsInstancesAndGroups) {
  // One row: car 9 and van 4 (both Cityscapes car: k in instance id order), a person without
  // instance (a group), a traffic sign with an instance id (no instances in Cityscapes), a class
  // beyond VIPER's table.
  const std::vector<uint8_t> classes = {24, 25, 24, 20, 14, 200, 2};
  const std::vector<int32_t> instances = {9, 4, 9, 0, 5, 0, 0};
  const auto gt = ds::cityscapesGroundTruth(classes.data(), instances.data(), 7, 1);
  EXPECT_EQ(gt.label_ids, (std::vector<uint8_t>{26, 26, 26, 24, 20, 0, 23}));
  EXPECT_EQ(gt.instance_ids, (std::vector<uint16_t>{26001, 26000, 26001, 24, 20, 0, 23}));
  EXPECT_EQ(gt.train_ids, (std::vector<uint8_t>{13, 13, 13, 11, 7, 255, 10}));
  EXPECT_EQ(gt.group_pixels, 1u);
  EXPECT_EQ(gt.color_rgba[0 * 4 + 2], 142);  // car (0, 0, 142)
  EXPECT_EQ(gt.color_rgba[6 * 4 + 0], 70);   // sky (70, 130, 180)
  EXPECT_EQ(gt.color_rgba[6 * 4 + 3], 255);
}

TEST(Cityscapes, InstancesBeyondTheThousandthBecomeGroups) {
  std::vector<uint8_t> classes(1002, 24);
  std::vector<int32_t> instances(1002);
  for (int i = 0; i < 1002; ++i) instances[i] = i + 1;
  const auto gt = ds::cityscapesGroundTruth(classes.data(), instances.data(), 1002, 1);
  EXPECT_EQ(gt.instance_ids[999], 26999);
  EXPECT_EQ(gt.instance_ids[1000], 26);
  EXPECT_EQ(gt.instance_ids[1001], 26);
  EXPECT_EQ(gt.instances_over_limit, 2u);
  EXPECT_EQ(gt.group_pixels, 2u);
}

TEST(Cityscapes, RefusesNamesItsReadersWouldMisread) {
  ds::CityscapesFrameName name;
  name.sequence = 12;
  name.frame = 345;
  EXPECT_EQ(name.stem(), "viper_000012_000345");
  name.city = "my_city";
  EXPECT_THROW(name.stem(), std::invalid_argument);
  name.city = "x";
  name.frame = 1000000;
  EXPECT_THROW(name.stem(), std::invalid_argument);
}

TEST(Cityscapes, EveryViperClassHasACityscapesLabel) {
  // config/viper_classes.csv's 32 classes; the mapping's reasons: docs/training_formats.md.
  const auto& labels = ds::cityscapesLabels();
  ASSERT_EQ(labels.size(), 34u);
  for (int id = 0; id < 34; ++id) EXPECT_EQ(labels[id].id, id);
  std::ifstream csv("config/viper_classes.csv");
  std::string line;
  std::getline(csv, line);
  int rows = 0;
  const std::map<std::string, std::string> expected = {
      {"sky", "sky"}, {"road", "road"}, {"sidewalk", "sidewalk"}, {"railtrack", "rail track"},
      {"terrain", "terrain"}, {"tree", "vegetation"}, {"vegetation", "vegetation"}, {"building", "building"},
      {"infrastructure", "pole"}, {"fence", "fence"}, {"trafficlight", "traffic light"},
      {"trafficsign", "traffic sign"}, {"person", "person"}, {"bicycle", "bicycle"},
      {"motorcycle", "motorcycle"}, {"car", "car"}, {"van", "car"}, {"bus", "bus"}, {"truck", "truck"},
      {"trailer", "trailer"}, {"train", "train"}};
  while (std::getline(csv, line)) {
    std::istringstream fields(line);
    std::string id, name;
    std::getline(fields, id, ',');
    std::getline(fields, name, ',');
    const auto& label = labels[ds::cityscapesLabelOfViperClass(std::stoi(id))];
    if (expected.count(name))
      EXPECT_EQ(label.name, expected.at(name)) << name;
    else  // no Cityscapes class of its own: one of the void labels
      EXPECT_TRUE(label.id == 0 || label.id == 4 || label.id == 5) << name << " -> " << label.name;
    ++rows;
  }
  EXPECT_EQ(rows, 32);
}

}  // namespace
