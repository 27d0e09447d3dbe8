// Dataset statistics on a small dataset written by the package's own layout writers, whose content
// is known pixel by pixel and box by box: exact counts in every CSV, the Jensen-Shannon divergence
// against values worked out by hand, the report's files, and a damaged file named while the rest is
// counted.
#include "viper/dataset/dataset_statistics.h"
#include "viper/dataset/statistics_report.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_images.h"
#include "viper/dataset/viper_layout.h"

#include "../common/process_util.h"
#include "dataset_test_util.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>

namespace {

using namespace viper::dataset;
using viper_dataset_test::readBytes;
using viper_dataset_test::TempDir;
using viper_dataset_test::writeBytes;
using viper::test::readFile;
namespace fs = std::filesystem;

// Class ids of config/viper_classes.csv.
constexpr uint8_t kUnlabeled = 0, kAmbiguous = 1, kSky = 2, kRoad = 3, kBuilding = 9, kPerson = 20, kCar = 24,
                  kTruck = 27;

// One 4x2 frame: a class per pixel, an instance id per pixel (0 = none), its boxes.
struct Frame {
  std::vector<uint8_t> classes;
  std::vector<uint16_t> ids;
  std::vector<ViperBoxRow> boxes;
};

// A box of the given class whose model box is `min`..`max` and whose model origin sits at `t` in
// the camera frame; `visible` false gives the 2D box of an object without a visible pixel.
ViperBoxRow box(int class_id, int64_t id, std::array<double, 3> min, std::array<double, 3> max,
                std::array<double, 3> t, bool visible = true) {
  ViperBoxRow row;
  row.class_id = class_id, row.instance_id = id;
  row.box_2d = visible ? std::array<double, 4>{0, 0, 1, 1} : std::array<double, 4>{-1, -1, -1, -1};
  row.box_3d = {min[0], min[1], min[2], max[0], max[1], max[2]};
  row.model_to_camera[3] = t[0], row.model_to_camera[7] = t[1], row.model_to_camera[11] = t[2];
  return row;
}

void writeFrame(const std::string& root, const std::string& split, const std::string& seq, uint64_t n,
                const Frame& f) {
  for (const char* m : {"cls", "inst", "bb"}) fs::create_directories(fs::path(root) / split / m / seq);
  Image8 cls{4, 2, 1, f.classes}, inst{4, 2, 3, {}};
  for (size_t i = 0; i < f.classes.size(); ++i)
    inst.data.insert(inst.data.end(), {f.classes[i], static_cast<uint8_t>(f.ids[i] >> 8), static_cast<uint8_t>(f.ids[i] & 255)});
  writeViperClassImage(viperFramePath(root, split, "cls", seq, n, "png"), cls, {});
  writeViperInstanceImage(viperFramePath(root, split, "inst", seq, n, "png"), inst);
  writeViperBoxesCsv(viperFramePath(root, split, "bb", seq, n, "csv"), f.boxes);
}

// train/001 (day): 4 and 3 scored classes; 2 and 1 instances; cars at 15 m, 5 m, 29.03 m (the centre
// of a box that is not centred on its origin), an invisible car and a person (neither a vehicle).
// val/002 (day): 4 and 3 classes; 2 and 2 instances (one car's pixels in two runs); a truck at 45 m.
// test/003 (night): 2 scored classes, sky and building (unlabeled and ambiguous are not scored); no
// instance (the building has an id, but building is no instance class).
std::vector<StatisticsSequence> writeDataset(const std::string& root) {
  writeFrame(root, "train", "001", 0,
             {{kSky, kSky, kRoad, kRoad, kCar, kCar, kPerson, kUnlabeled},
              {0, 0, 0, 0, 5, 5, 7, 0},
              {box(kCar, 5, {-1, -1, -1}, {1, 1, 1}, {0, 0, -15}), box(kPerson, 7, {-1, -1, -1}, {1, 1, 1}, {0, 0, -5})}});
  writeFrame(root, "train", "001", 1,
             {{kSky, kSky, kSky, kRoad, kRoad, kRoad, kCar, kCar},
              {0, 0, 0, 0, 0, 0, 5, 5},
              {box(kCar, 5, {-1, -1, -1}, {1, 1, 1}, {3, 0, -4}), box(kCar, 8, {0, 0, 0}, {2, 2, 2}, {0, 0, -30}),
               box(kCar, 9, {-1, -1, -1}, {1, 1, 1}, {0, 0, -25}, false)}});
  writeFrame(root, "val", "002", 0,
             {{kSky, kRoad, kCar, kCar, kPerson, kPerson, kUnlabeled, kUnlabeled},
              {0, 0, 1, 1, 2, 2, 0, 0},
              {box(kTruck, 1, {-2, -2, -2}, {2, 2, 2}, {0, 0, -45})}});
  writeFrame(root, "val", "002", 1,
             {{kSky, kRoad, kRoad, kRoad, kCar, kCar, kCar, kCar}, {0, 0, 0, 0, 1, 1, 3, 1}, {}});
  writeFrame(root, "test", "003", 0,
             {{kUnlabeled, kUnlabeled, kAmbiguous, kAmbiguous, kSky, kSky, kSky, kBuilding}, {0, 0, 0, 0, 0, 0, 0, 4}, {}});
  return {{"train", "001", "day"}, {"val", "002", "day"}, {"test", "003", "night"}};
}

viper::ClassTable classTable() { return viper::ClassTable::load(VIPER_CLASS_TABLE); }

// divergence.csv's value for one statistic and pair.
double divergence(const std::string& csv, const std::string& statistic, const std::string& between,
                  const std::string& a, const std::string& b) {
  std::istringstream in(csv);
  const std::string prefix = statistic + "," + between + "," + a + "," + b + ",";
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) return line.size() == prefix.size() ? NAN : std::stod(line.substr(prefix.size()));
  ADD_FAILURE() << "no row " << prefix << " in\n" << csv;
  return NAN;
}

TEST(JensenShannon, IdenticalDisjointAndAWorkedExample) {
  EXPECT_DOUBLE_EQ(jensenShannonBits({{1, 2}, {2, 6}}, {{1, 2}, {2, 6}}), 0.0);
  EXPECT_NEAR(jensenShannonBits({{1, 1}, {2, 3}}, {{1, 10}, {2, 30}}), 0.0, 1e-15) << "counts, not shares, differ";
  EXPECT_DOUBLE_EQ(jensenShannonBits({{0, 4}}, {{1, 9}, {2, 1}}), 1.0);
  // P = (1/2, 1/2), Q = (1, 0): M = (3/4, 1/4), H(M) = 0.8112781244591328 bits, H(P) = 1, H(Q) = 0,
  // JSD = H(M) - (H(P) + H(Q)) / 2 = 0.3112781244591328.
  EXPECT_NEAR(jensenShannonBits({{1, 1}, {2, 1}}, {{2, 5}}), 0.3112781244591328, 1e-12);
  EXPECT_NEAR(jensenShannonBits({{2, 5}}, {{1, 1}, {2, 1}}), 0.3112781244591328, 1e-12) << "symmetric";
  EXPECT_TRUE(std::isnan(jensenShannonBits({}, {{1, 1}}))) << "undefined for an empty side";
}

TEST(DatasetStatistics, KnownDatasetGivesExactCountsAndDivergences) {
  TempDir dir;
  const std::string root = dir / "data";
  const DatasetStatistics stats = computeDatasetStatistics(root, writeDataset(root), classTable());
  EXPECT_TRUE(stats.problems.empty()) << stats.problems.front();
  const std::vector<std::string> written = writeStatisticsReport(stats, root, "known");
  EXPECT_EQ(written.size(), 2 * allStatistics().size() + 2);
  const std::string out = root + "/statistics/";

  EXPECT_EQ(readFile(out + "classes_per_image.csv"),
            "split,condition,bin,count\ntrain,day,3,1\ntrain,day,4,1\nval,day,3,1\nval,day,4,1\ntest,night,2,1\n");
  EXPECT_EQ(readFile(out + "instances_per_image.csv"),
            "split,condition,bin,count\ntrain,day,1,1\ntrain,day,2,1\nval,day,2,2\ntest,night,0,1\n");
  EXPECT_EQ(readFile(out + "instances_per_class.csv"),
            "split,condition,bin,count\ntrain,day,person,1\ntrain,day,car,2\nval,day,person,1\nval,day,car,3\n");
  EXPECT_EQ(readFile(out + "vehicles_by_distance.csv"),
            "split,condition,bin,count\ntrain,day,0,1\ntrain,day,10,1\ntrain,day,20,1\nval,day,40,1\n");
  EXPECT_EQ(readFile(out + "pixels_per_class.csv"),
            "split,condition,bin,count\n"
            "train,day,unlabeled,1\ntrain,day,sky,5\ntrain,day,road,5\ntrain,day,person,1\ntrain,day,car,4\n"
            "val,day,unlabeled,2\nval,day,sky,2\nval,day,road,4\nval,day,person,2\nval,day,car,6\n"
            "test,night,unlabeled,2\ntest,night,ambiguous,2\ntest,night,sky,3\ntest,night,building,1\n");

  const std::string jsd = readFile(out + "divergence.csv");
  EXPECT_EQ(jsd.rfind("statistic,between,a,b,jsd_bits\n", 0), 0u) << jsd;
  EXPECT_DOUBLE_EQ(divergence(jsd, "classes_per_image", "split", "train", "val"), 0.0) << "identical";
  EXPECT_DOUBLE_EQ(divergence(jsd, "instances_per_image", "split", "train", "test"), 1.0) << "disjoint";
  EXPECT_NEAR(divergence(jsd, "instances_per_image", "split", "train", "val"), 0.3112781244591328, 1e-12);
  EXPECT_DOUBLE_EQ(divergence(jsd, "instances_per_image", "condition", "day", "night"), 1.0);
  EXPECT_TRUE(std::isnan(divergence(jsd, "vehicles_by_distance", "split", "train", "test"))) << "test has none";

  const std::string md = readFile(root + "/statistics.md");
  EXPECT_NE(md.find("5 images (frames with a cls or inst file) in 3 sequences"), std::string::npos) << md;
  EXPECT_NE(md.find("| train | day | 1 | 2 | 3.50 | 1.50 | 3 | 3 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| instances per image | 0.311 | 1.000 | 1.000 |"), std::string::npos) << md;
  EXPECT_NE(md.find("(motorcycle, car, van, bus, truck)"), std::string::npos) << md;
  for (Statistic s : allStatistics()) {
    const std::string png = std::string("statistics/") + statisticName(s) + ".png";
    EXPECT_NE(md.find("](" + png + ")"), std::string::npos) << "links " << png;
    const cv::Mat image = cv::imread(root + "/" + png);
    EXPECT_EQ(image.cols, 1280) << png;
    EXPECT_EQ(image.rows, 420) << png;
  }
}

TEST(DatasetStatistics, ADamagedFileIsNamedAndTheRestCounted) {
  TempDir dir;
  const std::string root = dir / "data";
  const std::vector<StatisticsSequence> sequences = writeDataset(root);
  const std::string inst = viperFramePath(root, "val", "inst", "002", 1, "png");
  std::vector<uint8_t> bytes = readBytes(inst);
  bytes.resize(bytes.size() / 2);
  writeBytes(inst, bytes);
  const DatasetStatistics stats = computeDatasetStatistics(root, sequences, classTable());
  ASSERT_EQ(stats.problems.size(), 1u);
  EXPECT_EQ(stats.problems[0].rfind(inst, 0), 0u) << "starts with the file: " << stats.problems[0];
  const auto& val = stats.cells.at({"val", "day"});
  EXPECT_EQ(val.images, 2u) << "its cls file still counts the frame";
  EXPECT_EQ(val.histograms.at(Statistic::kInstancesPerImage), (Histogram{{2, 1}})) << "one inst file left";

  EXPECT_THROW(computeDatasetStatistics(root, {{"val", "009", "day"}}, classTable()), std::runtime_error);
  StatisticsOptions zero;
  zero.distance_bin_m = 0;
  EXPECT_THROW(computeDatasetStatistics(root, sequences, classTable(), zero), std::invalid_argument);
}

}  // namespace
