// The training formats' writers against what the formats' reference code read from their files
// (test/dataset/data/training_formats, made by scripts/training_formats_reference.sh from the frames
// of training_format_cases.h): the files written here, decoded by OpenCV, hold the values the
// reference's readers got, and the reference scored those files as perfect.
#include "dataset_test_util.h"
#include "training_format_cases.h"

#include "viper/dataset/cityscapes.h"
#include "viper/dataset/file_digests.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

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

struct Fixture {
  std::map<std::string, FileValues> files;
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
