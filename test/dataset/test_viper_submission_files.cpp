// The submission writers' own promises, without a bag: names, refusals before anything is written,
// instances.csv kept per sequence, errors naming the file and line, odometry read back.
#include "viper/dataset/viper_submission.h"

#include "dataset_test_util.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

using namespace viper::dataset;
using viper_dataset_test::TempDir;

Image8 mask(uint32_t width, uint32_t height, size_t inside) {
  Image8 m{width, height, 1, std::vector<uint8_t>(size_t(width) * height)};
  m.data.at(inside) = 7;
  return m;
}

TEST(SubmissionFiles, NamesAreVipersAndOutOfRangeIdsAreRefused) {
  EXPECT_EQ(submissionFrameName(2, 3), "002_00003");
  EXPECT_EQ(submissionFrameName(999, 99999), "999_99999");
  EXPECT_THROW(submissionFrameName(1000, 0), std::invalid_argument);
  EXPECT_THROW(submissionFrameName(-1, 0), std::invalid_argument);
  EXPECT_THROW(submissionFrameName(1, 100000), std::invalid_argument);
}

TEST(SubmissionFiles, InstancesAreNumberedPerClassAndBinary) {
  TempDir dir;
  const auto rows = writeSubmissionInstances(dir.path().string(), 2, 4,
                                             {{24, 0.75, mask(4, 3, 0)}, {20, 0.5, mask(4, 3, 5)}, {24, 0.6, mask(4, 3, 11)}});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].instance_id, 1);
  EXPECT_EQ(rows[1].instance_id, 1);
  EXPECT_EQ(rows[2].instance_id, 2);
  const Image8 second_car = readViperClassImage(dir / "002_00004_24_2.png");
  for (size_t i = 0; i < second_car.data.size(); ++i) EXPECT_EQ(second_car.data[i], i == 11 ? 255 : 0) << i;
}

TEST(SubmissionFiles, BadInstancesAreRefusedBeforeAnythingIsWritten) {
  TempDir dir;
  EXPECT_THROW(writeSubmissionInstances(dir.path().string(), 1, 0, {{24, 0.5, mask(4, 3, 0)}, {24, 1.5, mask(4, 3, 0)}}),
               std::invalid_argument);
  EXPECT_THROW(writeSubmissionInstances(dir.path().string(), 1, 0, {{24, 0.5, mask(4, 3, 0)}, {24, 0.5, mask(3, 3, 0)}}),
               std::invalid_argument);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(SubmissionFiles, InstancesCsvKeepsOtherSequencesAndReplacesItsOwn) {
  TempDir dir;
  const std::string d = dir.path().string();
  writeInstancesCsv(d, 2, {{2, 4, 24, 1, 0.75}, {2, 4, 24, 2, 0.5}});
  writeInstancesCsv(d, 1, {{1, 9, 20, 1, 0.25}});
  writeInstancesCsv(d, 2, {{2, 5, 24, 1, 0.6}});
  const auto rows = readInstancesCsv(dir / "instances.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].sequence_id, 1);
  EXPECT_EQ(rows[1].frame, 5u);
  const std::vector<uint8_t> text = viper_dataset_test::readBytes(dir / "instances.csv");
  EXPECT_EQ(std::string(text.begin(), text.end()), "1,9,20,1,0.25\n2,5,24,1,0.6\n");  // EVALUATION.md's form
  const std::string bad = "1,2\n";
  viper_dataset_test::writeBytes(dir / "instances.csv", std::vector<uint8_t>(bad.begin(), bad.end()));
  viper_dataset_test::expectErrorNaming([&] { readInstancesCsv(dir / "instances.csv"); },
                                        {dir / "instances.csv", ":1:", "'1,2'"}, "a short row");
}

TEST(SubmissionFiles, OdometryOfOpticalEstimatesIsRelativeToTheFirst) {
  TempDir dir;
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = Eigen::Isometry3d::Identity();
  a.translate(Eigen::Vector3d(5, 6, 7));
  b = a * Eigen::Translation3d(0, 0, 2) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY());
  const auto poses = kittiSubmissionPoses({1.0, 1.0666667}, {a, b}, true);
  const std::string path = writeSubmissionOdometry(dir.path().string(), 3, poses);
  EXPECT_EQ(std::filesystem::path(path).filename(), "003.txt");
  const auto read = readSubmissionOdometry(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_DOUBLE_EQ(read[1].timestamp_s, 1.0667);
  EXPECT_LT((read[0].position).norm(), 1e-12);
  EXPECT_LT((read[1].position - Eigen::Vector3d(0, 0, 2)).norm(), 1e-9);  // 2 m forward: +z in KITTI
  EXPECT_NEAR(read[1].orientation.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()))),
              0.0, 1e-8);
  EXPECT_THROW(kittiSubmissionPoses({1.0}, {a, b}, true), std::invalid_argument);
}

}  // namespace
