// VIPER's camera CSV (one per sequence) and box CSV (one per frame): round trips, the column order
// on disk, headers and comments, and bad lines that are reported (file:line) and skipped while the
// others are read.
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"

#include "dataset_test_util.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

namespace {

using namespace viper::dataset;
using viper_dataset_test::TempDir;

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

ViperCameraRow cameraRow(uint64_t frame, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> v(-50.0f, 50.0f);
  ViperCameraRow r;
  r.frame = frame;
  for (auto& x : r.projection) x = v(rng);  // float values, as GL matrices are
  for (auto& x : r.view) x = v(rng);
  return r;
}

bool mentions(const std::vector<std::string>& problems, const std::string& a, const std::string& b) {
  for (const auto& p : problems)
    if (p.find(a) != std::string::npos && p.find(b) != std::string::npos) return true;
  return false;
}

TEST(ViperCameraCsv, PathIsPerSequence) {
  EXPECT_EQ(viperCameraPath("/d", "train", "001"), "/d/train/camera/001.csv");
  EXPECT_THROW(viperCameraPath("/d", "train", "0_1"), std::invalid_argument);
}

TEST(ViperCameraCsv, ColumnsAreFrameThenProjectionThenViewRowByRow) {
  ViperCameraRow r;
  r.frame = 7;
  for (int i = 0; i < 16; ++i) r.projection[i] = i + 1, r.view[i] = 100 + i;
  const std::string line = formatViperCameraRow(r);
  EXPECT_EQ(line, "7,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,100,101,102,103,104,105,106,107,108,109,110,111,112,113,114,115");
}

TEST(ViperCameraCsv, RoundTripsFloatMatricesExactly) {
  TempDir dir;
  std::vector<ViperCameraRow> rows;
  for (uint64_t f = 0; f < 20; ++f) rows.push_back(cameraRow(f * 3, static_cast<uint32_t>(f)));
  rows[4].view[3] = 1.0e-7, rows[5].view[7] = -123456.789;  // tiny and large values
  writeViperCameraCsv(dir / "c.csv", rows);
  std::vector<std::string> problems;
  const auto back = readViperCameraCsv(dir / "c.csv", problems);
  EXPECT_TRUE(problems.empty());
  ASSERT_EQ(back.size(), rows.size());
  for (const auto& r : rows) {
    ASSERT_TRUE(back.count(r.frame));
    for (int i = 0; i < 16; ++i) {
      EXPECT_EQ(static_cast<float>(back.at(r.frame).projection[i]), static_cast<float>(r.projection[i]));
      EXPECT_EQ(static_cast<float>(back.at(r.frame).view[i]), static_cast<float>(r.view[i]));
    }
  }
}

TEST(ViperCameraCsv, BadLinesAreNamedAndSkipped) {
  TempDir dir;
  const std::string good0 = formatViperCameraRow(cameraRow(0, 1));
  const std::string good1 = formatViperCameraRow(cameraRow(1, 2));
  const std::string good5 = formatViperCameraRow(cameraRow(5, 3));
  std::string short_line = formatViperCameraRow(cameraRow(2, 4));
  short_line = short_line.substr(0, short_line.rfind(','));
  std::string word = formatViperCameraRow(cameraRow(3, 5));
  word.replace(word.find(',', 3) + 1, 1, "x");
  const std::string nan = "4" + std::string(",nan") + formatViperCameraRow(cameraRow(4, 6)).substr(formatViperCameraRow(cameraRow(4, 6)).find(',', 2));
  std::string negative = formatViperCameraRow(cameraRow(6, 7));
  negative[0] = '-';
  writeText(dir / "c.csv", "frame,p00,p01\n" + good0 + "\n\n# a comment\n" + good1 + "\n" + short_line + "\n" + word +
                               "\n" + nan + "\n" + good5 + "\n" + negative + "\n" + good1 + "\n");
  std::vector<std::string> problems;
  const auto rows = readViperCameraCsv(dir / "c.csv", problems);
  EXPECT_EQ(rows.size(), 3u);
  EXPECT_TRUE(rows.count(0) && rows.count(1) && rows.count(5));
  EXPECT_EQ(problems.size(), 5u);
  EXPECT_TRUE(mentions(problems, dir / "c.csv:6:", "32 values, expected 33"));
  EXPECT_TRUE(mentions(problems, dir / "c.csv:7:", "is not a number"));
  EXPECT_TRUE(mentions(problems, dir / "c.csv:8:", "not finite"));
  EXPECT_TRUE(mentions(problems, dir / "c.csv:10:", "frame id"));
  EXPECT_TRUE(mentions(problems, dir / "c.csv:11:", "already given on line 5"));
}

TEST(ViperCameraCsv, MissingFileThrowsNamingIt) {
  TempDir dir;
  std::vector<std::string> problems;
  viper_dataset_test::expectErrorNaming([&] { readViperCameraCsv(dir / "none.csv", problems); },
                                        {dir / "none.csv", "cannot open"}, "missing");
}

ViperBoxRow boxRow(int cls, int64_t id) {
  ViperBoxRow r;
  r.class_id = cls;
  r.instance_id = id;
  r.box_2d = {{10, 20, 30.5, 40}};
  r.box_3d = {{-1, -0.5, -2, 1, 0.5, 2}};
  for (int i = 0; i < 16; ++i) r.model_to_camera[i] = 0.25 * i - 1;
  return r;
}

TEST(ViperBoxesCsv, ColumnsAndRoundTrip) {
  TempDir dir;
  EXPECT_EQ(formatViperBoxRow(boxRow(24, 7)),
            "24,7,10,20,30.5,40,-1,-0.5,-2,1,0.5,2,-1,-0.75,-0.5,-0.25,0,0.25,0.5,0.75,1,1.25,1.5,1.75,2,2.25,2.5,2.75");
  const std::vector<ViperBoxRow> rows = {boxRow(24, 7), boxRow(20, 65536), boxRow(13, 0)};
  writeViperBoxesCsv(dir / "b.csv", rows);
  std::vector<std::string> problems;
  const auto back = readViperBoxesCsv(dir / "b.csv", problems);
  EXPECT_TRUE(problems.empty());
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[1].instance_id, 65536);
  EXPECT_EQ(back[1].class_id, 20);
  EXPECT_EQ(back[0].box_2d, rows[0].box_2d);
  EXPECT_EQ(back[0].box_3d, rows[0].box_3d);
  EXPECT_EQ(back[0].model_to_camera, rows[0].model_to_camera);
  writeViperBoxesCsv(dir / "empty.csv", {});
  EXPECT_TRUE(readViperBoxesCsv(dir / "empty.csv", problems).empty());
  EXPECT_TRUE(problems.empty());
}

TEST(ViperBoxesCsv, BadLinesAreNamedAndSkipped) {
  TempDir dir;
  const std::string good = formatViperBoxRow(boxRow(24, 7));
  std::string big_class = good;
  big_class.replace(0, 2, "300");
  std::string fraction = good;
  fraction.replace(3, 1, "7.5");
  writeText(dir / "b.csv", "class,instance,...\n" + good + "\n" + good + ",1\n" + big_class + "\n" + fraction + "\n" +
                               good.substr(0, good.size() - 4) + "inf\n" + good + "\n");
  std::vector<std::string> problems;
  const auto rows = readViperBoxesCsv(dir / "b.csv", problems);
  EXPECT_EQ(rows.size(), 2u);
  EXPECT_EQ(problems.size(), 4u);
  EXPECT_TRUE(mentions(problems, dir / "b.csv:3:", "29 values, expected 28"));
  EXPECT_TRUE(mentions(problems, dir / "b.csv:4:", "class id '300'"));
  EXPECT_TRUE(mentions(problems, dir / "b.csv:5:", "instance id '7.5'"));
  EXPECT_TRUE(mentions(problems, dir / "b.csv:6:", "not finite"));
}

}  // namespace
