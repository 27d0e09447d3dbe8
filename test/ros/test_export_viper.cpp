// The export_viper command on bags written here (rosbag C++ API, no roscore): bad messages are
// reported and skipped while the rest is exported (exit 1), a clean bag exports completely (exit
// 0), camera rows come from odometry + camera_info without a draw list, and a topic of the wrong
// type, a missing bag or bad options are errors (exit 2).
#include "../common/temp_dir.h"

#include "viper/dataset/viper_images.h"
#include "viper/dataset/viper_layout.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <random>

namespace {

namespace fs = std::filesystem;
using namespace viper;

struct CommandResult {
  int code = -1;
  std::string output;
};

// With `limit_kib`, under a file-size limit (SIGXFSZ ignored: a write fails as on a full disk).
CommandResult exportViper(const std::string& args, int limit_kib = 0) {
  CommandResult r;
  std::string command = std::string(VIPER_EXPORT_VIPER) + " " + args;
  if (limit_kib > 0) command = "sh -c \"trap '' XFSZ; ulimit -f " + std::to_string(limit_kib) + "; exec " + command + "\"";
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, p)) > 0) r.output.append(buffer, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

class ExportViper : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return dir_ / name; }
  std_msgs::Header header(int frame) const {
    std_msgs::Header h;
    h.stamp = ros::Time(100 + frame / 15.0);
    h.frame_id = "camera_optical";
    return h;
  }
  viper::test::TempDir dir_{"viper_export_"};
};

TEST_F(ExportViper, BadMessagesAreSkippedAndTheRestExported) {
  rosbag::Bag bag(path("gt.bag"), rosbag::bagmode::Write);
  const std::vector<uint8_t> rgb(4 * 3 * 3, 90), ids8(4 * 3, 24);
  const std::vector<int32_t> ids(4 * 3, 5);
  const std::vector<float> flow(4 * 3 * 2, 0.5f);
  for (int f = 0; f < 4; ++f) {
    const ros::Time t = header(f).stamp;
    bag.write("/capture/color/image_raw", t, imageMsg(header(f), 4, 3, "rgb8", 3, rgb.data()));
    sensor_msgs::Image semantic = imageMsg(header(f), 4, 3, "mono8", 1, ids8.data());
    if (f == 2) semantic.encoding = "mono16";  // bad
    bag.write("/ground_truth/semantic", t, semantic);
    bag.write("/ground_truth/instance_ids", t, imageMsg(header(f), 4, 3, "32SC1", 4, ids.data()));
    sensor_msgs::Image fl = imageMsg(header(f), 4, 3, "32FC2", 8, flow.data());
    if (f == 1) fl.data.resize(10);  // bad
    if (f < 3) bag.write("/ground_truth/flow/forward", t, fl);
    nav_msgs::Odometry odom;
    odom.header = header(f);
    odom.pose.pose.orientation.w = 1;
    odom.pose.pose.position.x = f;
    bag.write("/ground_truth/odom", t, odom);
    sensor_msgs::CameraInfo info;
    info.header = header(f);
    info.width = 4, info.height = 3;
    info.K = {{4, 0, 1.5, 0, 4, 1, 0, 0, 1}};
    bag.write("/capture/color/camera_info", t, info);
  }
  std_msgs::Header stray = header(9);  // a stamp the camera images never had
  bag.write("/ground_truth/semantic", stray.stamp, imageMsg(stray, 4, 3, "mono8", 1, ids8.data()));
  bag.close();

  const CommandResult r = exportViper("--bag " + path("gt.bag") + " --out " + path("out") + " --seq 042");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("skipping /ground_truth/semantic at stamp 100.13333333"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(frame 2): encoding is 'mono16', expected mono8"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(frame 1): data has 10 bytes, step * height is 96"),
            std::string::npos) << r.output;
  EXPECT_NE(r.output.find("skipping /ground_truth/semantic at stamp 100.6"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": its stamp is not among the 4 stamps of /capture/color/image_raw"),
            std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frame 2: instance ids without semantic: no inst file"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("camera rows 4 (odom)"), std::string::npos) << r.output;

  const dataset::ViperSequenceFiles files = dataset::scanViperSequence(path("out"), "train", "042");
  EXPECT_EQ(files.files.at(dataset::ViperModality::kImg).size(), 4u);
  EXPECT_EQ(files.files.at(dataset::ViperModality::kCls).size(), 3u);
  EXPECT_EQ(files.files.at(dataset::ViperModality::kInst).size(), 3u);
  EXPECT_EQ(files.files.at(dataset::ViperModality::kFlow).size(), 2u);
  std::vector<std::string> problems;
  const auto camera = dataset::readViperCameraCsv(files.camera_csv, problems);
  ASSERT_EQ(camera.size(), 4u);
  EXPECT_NEAR(camera.at(3).view[11], 3, 1e-9) << "3 m forward: the camera at z = -3 in the first camera's axes";
  EXPECT_EQ(camera.at(0).view, dataset::identity4());
  const dataset::ViperFrame f = dataset::readViperFrame(files, 3, camera, {dataset::ViperModality::kInst}, problems);
  ASSERT_TRUE(f.inst);
  EXPECT_EQ(f.inst->data[0], 24);
  EXPECT_EQ(f.inst->data[2], 5);
}

TEST_F(ExportViper, ErrorsEndWithExitCode2) {
  {
    rosbag::Bag bag(path("wrong.bag"), rosbag::bagmode::Write);
    sensor_msgs::CameraInfo info;
    info.header = header(0);
    bag.write("/ground_truth/semantic", info.header.stamp, info);
  }
  CommandResult r = exportViper("--bag " + path("wrong.bag") + " --out " + path("out"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("/ground_truth/semantic (semantic) in " + path("wrong.bag") +
                          " carries sensor_msgs/CameraInfo, expected sensor_msgs/Image"),
            std::string::npos) << r.output;
  r = exportViper("--bag " + path("none.bag") + " --out " + path("out"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("cannot open bag"), std::string::npos) << r.output;
  r = exportViper("--bag " + path("wrong.bag") + " --out " + path("out") + " --seq a_b");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("'a_b' holds '_'"), std::string::npos) << r.output;
  r = exportViper("--bag x --live --out " + path("out"));
  EXPECT_EQ(r.code, 2);
  r = exportViper("--bag " + path("wrong.bag") + " --out " + path("out") + " --topic color");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--topic takes ROLE=TOPIC"), std::string::npos) << r.output;
}

// A full disk: the frames before the one that does not fit are written whole, the error names the
// file, the exit code is 2.
TEST_F(ExportViper, FullDiskNamesTheFileAndKeepsTheFramesBefore) {
  {
    rosbag::Bag bag(path("gt.bag"), rosbag::bagmode::Write);
    const uint32_t w = 320, h = 240;
    std::mt19937 rng(7);
    for (int f = 0; f < 4; ++f) {
      // Flat frames deflate to a few hundred bytes; noise does not fit under the limit.
      std::vector<uint8_t> rgb(w * h * 3, 90);
      if (f == 2)
        for (uint8_t& v : rgb) v = static_cast<uint8_t>(rng());
      bag.write("/capture/color/image_raw", header(f).stamp, imageMsg(header(f), w, h, "rgb8", 3, rgb.data()));
    }
  }
  const CommandResult r = exportViper("--bag " + path("gt.bag") + " --out " + path("out") + " --camera none", 100);
  EXPECT_EQ(r.code, 2) << r.output;
  const std::string failed = path("out") + "/train/img/001/001_00002.png";
  EXPECT_NE(r.output.find(failed + ": cannot write PNG: File too large"), std::string::npos) << r.output;
  for (int f = 0; f < 2; ++f) {
    const dataset::Image8 img = dataset::readViperColorImage(path("out") + "/train/img/001/001_0000" + std::to_string(f) + ".png");
    EXPECT_EQ(img.width, 320u);
    EXPECT_EQ(img.data[0], 90);
  }
  EXPECT_FALSE(fs::exists(failed)) << "no half-written file under the final name";
}

}  // namespace
