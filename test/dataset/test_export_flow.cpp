// export_flow end to end: a bag of 32FC2 flow images (with bad ones among them) made here with
// the rosbag API, the real command run on it, and the files it wrote read back.
#include "viper/dataset/float16.h"
#include "viper/dataset/middlebury_flo.h"
#include "viper/dataset/viper_flow.h"

#include "dataset_test_util.h"

#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace {

using namespace viper::dataset;
using viper_dataset_test::TempDir;

int runExport(const std::string& args, std::string& out) {
  return viper_dataset_test::runCommand(std::string(VIPER_EXPORT_FLOW) + " " + args, out);
}

// A width x height flow that differs per frame, with NaN pixels, one out-of-range value and
// values that float16 cannot hold exactly.
FlowImage makeFlow(uint32_t width, uint32_t height, int frame) {
  FlowImage f;
  f.width = width;
  f.height = height;
  f.uv.resize(2 * f.pixels());
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const size_t i = y * width + x;
      f.uv[2 * i] = 0.37f * x - 1.01f * y + 10.3f * frame;
      f.uv[2 * i + 1] = -0.013f * x * y + 0.5f * frame;
    }
  f.uv[2 * 3] = std::nanf("");
  f.uv[2 * 5 + 1] = std::nanf("");
  if (f.pixels() > 7) f.uv[2 * 7] = 70000.0f;  // beyond float16: inf in the npz, exact in the .flo
  return f;
}

sensor_msgs::Image toMessage(const FlowImage& f, const ros::Time& stamp, uint32_t padding = 0, bool big_endian = false) {
  sensor_msgs::Image m;
  m.header.stamp = stamp;
  m.header.frame_id = "camera_optical";
  m.width = f.width;
  m.height = f.height;
  m.encoding = "32FC2";
  m.is_bigendian = big_endian;
  m.step = f.width * 8 + padding;
  m.data.assign(static_cast<size_t>(m.step) * m.height, 0xee);
  for (uint32_t y = 0; y < f.height; ++y)
    std::memcpy(m.data.data() + y * m.step, f.uv.data() + 2 * y * f.width, f.width * 8);
  if (big_endian)
    for (uint32_t y = 0; y < f.height; ++y)
      for (uint32_t i = 0; i < 2 * f.width; ++i) std::reverse(&m.data[y * m.step + 4 * i], &m.data[y * m.step + 4 * i + 4]);
  return m;
}

void expectNpzHolds(const std::string& path, const FlowImage& in) {
  const FlowImage got = readViperFlow(path);
  ASSERT_EQ(got.width, in.width) << path;
  ASSERT_EQ(got.height, in.height) << path;
  for (size_t i = 0; i < in.uv.size(); ++i) {
    const float expected = halfToFloat(floatToHalf(in.uv[i]));
    if (std::isnan(expected)) EXPECT_TRUE(std::isnan(got.uv[i])) << path << " value " << i;
    else EXPECT_EQ(got.uv[i], expected) << path << " value " << i;
  }
}

void expectFloHolds(const std::string& path, const FlowImage& in) {
  const FlowImage got = readMiddleburyFlo(path);
  ASSERT_EQ(got.width, in.width) << path;
  ASSERT_EQ(got.height, in.height) << path;
  for (size_t p = 0; p < in.pixels(); ++p) {
    const bool unknown = std::isnan(in.uv[2 * p]) || std::isnan(in.uv[2 * p + 1]);
    for (size_t c = 0; c < 2; ++c) {
      if (unknown) EXPECT_TRUE(std::isnan(got.uv[2 * p + c])) << path << " pixel " << p;
      else EXPECT_EQ(got.uv[2 * p + c], in.uv[2 * p + c]) << path << " pixel " << p;
    }
  }
}

class ExportFlow : public ::testing::Test {
 protected:
  void SetUp() override {
    bag_ = dir_ / "flow.bag";
    rosbag::Bag bag(bag_, rosbag::bagmode::Write);
    const ros::Time t0(100, 0);
    const ros::Duration frame_time(0, 66666000);
    for (int i = 0; i < 5; ++i) {
      const ros::Time stamp = t0 + frame_time * i;
      flows_.push_back(makeFlow(6, 4, i));
      sensor_msgs::Image m;
      if (i == 1) {  // wrong encoding
        m = toMessage(flows_.back(), stamp);
        m.encoding = "rgb8";
      } else if (i == 3) {  // data shorter than step * height
        m = toMessage(flows_.back(), stamp);
        m.data.resize(m.data.size() - 8);
      } else if (i == 2) {  // rows padded
        m = toMessage(flows_.back(), stamp, 16);
      } else if (i == 4) {
        m = toMessage(flows_.back(), stamp, 0, true);
      } else {
        m = toMessage(flows_.back(), stamp);
      }
      bag.write("/ground_truth/flow/forward", stamp, m);
      sensor_msgs::Image other = toMessage(makeFlow(3, 2, 9), stamp);
      bag.write("/flow/backward", stamp, other);
    }
    // Camera frames at t0 - 1 frame, t0, t1, t3, t4: frame t2 was dropped.
    for (int i : {-1, 0, 1, 3, 4}) {
      sensor_msgs::Image color;
      color.header.stamp = t0 + frame_time * i;
      color.width = color.height = 2;
      color.encoding = "rgb8";
      color.step = 6;
      color.data.assign(12, 128);
      bag.write("/camera/color", color.header.stamp + ros::Duration(0.001), color);
    }
    bag.close();
  }

  TempDir dir_;
  std::string bag_;
  std::vector<FlowImage> flows_;
};

TEST_F(ExportFlow, WritesGoodMessagesAndReportsBadOnes) {
  const std::string out_dir = dir_ / "viper";
  std::string out;
  const int rc = runExport("--bag " + bag_ + " --out " + out_dir + " --format both --seq 007 --split val", out);
  EXPECT_EQ(rc, 1) << "bad messages were skipped: " << out;
  EXPECT_NE(out.find("skipping /ground_truth/flow/forward at stamp 100.066666000 (frame 1): encoding is 'rgb8', expected 32FC2"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("skipping /ground_truth/flow/forward at stamp 100.199998000 (frame 3): data has 184 bytes, step * height is 192"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("1 flow values of 65520 px or more became inf"), std::string::npos) << out;
  EXPECT_NE(out.find("5/5 messages (2 skipped)"), std::string::npos) << out;
  EXPECT_NE(out.find("wrote 3 of 5 messages"), std::string::npos) << out;

  const std::string seq_dir = out_dir + "/val/flow/007/";
  for (int i : {0, 2, 4}) {
    char name[32];
    std::snprintf(name, sizeof name, "007_%05d", i);
    SCOPED_TRACE(name);
    expectNpzHolds(seq_dir + name + ".npz", flows_[i]);
    expectFloHolds(seq_dir + name + ".flo", flows_[i]);
  }
  for (const char* absent : {"007_00001.npz", "007_00001.flo", "007_00003.npz", "007_00005.npz"})
    EXPECT_FALSE(std::filesystem::exists(seq_dir + absent)) << absent;
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(seq_dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 6u) << "no temporary files left behind";
}

TEST_F(ExportFlow, DefaultsAndOtherTopic) {
  const std::string out_dir = dir_ / "viper";
  std::string out;
  const int rc = runExport("--bag " + bag_ + " --out " + out_dir + " --topic /flow/backward --modality flowbw --first-frame 20", out);
  EXPECT_EQ(rc, 0) << out;
  for (int frame = 20; frame < 25; ++frame) {
    char name[64];
    std::snprintf(name, sizeof name, "/train/flowbw/001/001_%05d.npz", frame);
    expectNpzHolds(out_dir + name, makeFlow(3, 2, 9));
  }
  EXPECT_FALSE(std::filesystem::exists(out_dir + "/train/flowbw/001/001_00020.flo")) << "npz is the default format";
}

TEST_F(ExportFlow, FramesNumberedByTheStampsOfAnotherTopic) {
  // Backward flow is stamped with the later frame: numbered by the camera's frames it lands on
  // 1, 2, 3, 4, and the flow stamped with the dropped frame t2 has no number.
  const std::string out_dir = dir_ / "viper";
  std::string out;
  const int rc = runExport("--bag " + bag_ + " --out " + out_dir + " --topic /flow/backward --modality flowbw" +
                               " --frames-from /camera/color --format flo",
                           out);
  EXPECT_EQ(rc, 1) << out;
  EXPECT_NE(out.find("skipping /flow/backward at stamp 100.133332000 (message 2): its stamp is not among the 5 stamps "
                     "of /camera/color"),
            std::string::npos)
      << out;
  for (int frame : {1, 2, 3, 4}) {
    char name[64];
    std::snprintf(name, sizeof name, "/train/flowbw/001/001_%05d.flo", frame);
    expectFloHolds(out_dir + name, makeFlow(3, 2, 9));
  }
  EXPECT_FALSE(std::filesystem::exists(out_dir + "/train/flowbw/001/001_00000.flo"));
  EXPECT_FALSE(std::filesystem::exists(out_dir + "/train/flowbw/001/001_00005.flo"));

  out.clear();
  EXPECT_EQ(runExport("--bag " + bag_ + " --out " + out_dir + " --topic /flow/backward --frames-from /nothing", out), 2);
  EXPECT_NE(out.find("has no messages on /nothing (--frames-from)"), std::string::npos) << out;
}

TEST_F(ExportFlow, UsageAndBagErrors) {
  std::string out;
  EXPECT_EQ(runExport("--bag " + bag_ + " --out " + (dir_ / "o") + " --topic /nothing", out), 2);
  EXPECT_NE(out.find("no messages on /nothing"), std::string::npos) << out;
  EXPECT_NE(out.find("/ground_truth/flow/forward (sensor_msgs/Image)"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(runExport("--bag " + (dir_ / "none.bag") + " --out " + (dir_ / "o"), out), 2);
  EXPECT_NE(out.find("cannot open bag"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(runExport("--bag " + bag_ + " --out " + (dir_ / "o") + " --seq my_seq", out), 2);
  EXPECT_NE(out.find("my_seq"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(runExport("--bag " + bag_ + " --out " + (dir_ / "o") + " --format png", out), 2);
  EXPECT_NE(out.find("--format"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(runExport("--out " + (dir_ / "o"), out), 2);
  EXPECT_NE(out.find("usage"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "o/train/flow/001/001_00000.npz"));
}

}  // namespace
