// Tests of VIPER layout interop with the real nodes; each .test file runs one of them
// (--gtest_filter):
//  - PlaysGoodFramesAndNamesEveryDamagedFile: the player (node or nodelet, started by the .test file) plays
//    make_viper_test_layout's dataset; every damaged file is reported on /rosout naming it, every
//    good frame is published on every topic it has data for, with the right stamps, encodings,
//    content, poses, boxes and camera_info, paced at ~rate;
//  - LoopsWithIncreasingStampsAndClock: the player loops: stamps and /clock keep increasing, problems are logged once;
//  - GroundTruthExportPlayerGiveIdenticalTopics (viper_layout_roundtrip.cpp): the committed raw bag
//    through the ground-truth nodelets (replay.launch), recorded into a bag here, export_viper into
//    the layout (the live exporter, in this process, writes the same files from the live topics),
//    generate in lockstep (the same ground truth and layout), the player (in this process) back to
//    topics: images identical, flow identical to float16, poses, boxes and intrinsics equal within
//    float precision; viper_to_bag of the layout gives the player's messages.
// Private parameters: timeout_s (120); the round trip's are in viper_layout_roundtrip.cpp.
#include "tester_main.h"
#include "bag_publishers.h"
#include "viper_layout_tester_support.h"
#include "../common/process_util.h"
#include "viper_test_layout.h"

#include "viper/ground_truth/ego_motion.h"
#include "viper/dataset/float16.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/dataset/viper_exporter_node.h"
#include "viper/ros/dataset/player.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <topic_tools/shape_shifter.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <sys/wait.h>

#include <cmath>
#include <deque>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <set>

namespace {

namespace fs = std::filesystem;
using namespace viper_test_layout;

double stampOf(uint64_t index) { return 1.0 + static_cast<double>(index) / 15.0; }

Eigen::Isometry3d expectedMapFromBody(uint64_t frame) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(kStepM * frame, 0, 0);
  t.linear() = Eigen::AngleAxisd(kYawRad * frame, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return t;
}

// Each test: two spinner threads, a deadline timeout_s from its start, and the player's /rosout
// lines from the time it connects, so that no problem it logs once it has subscribers is missed.
class ViperLayoutPlayer : public ::testing::Test {
 protected:
  void SetUp() override {
    spinner_.start();
    ASSERT_TRUE(waitFor([&] { return rosout_.publishers() >= 2; }, deadline_))
        << "the player never connected to /rosout";
  }

  ros::NodeHandle nh_, pnh_{"~"};
  ros::AsyncSpinner spinner_{2};
  const ros::WallTime deadline_ = ros::WallTime::now() + ros::WallDuration(pnh_.param("timeout_s", 120.0));
  Rosout rosout_{nh_};
};

TEST_F(ViperLayoutPlayer, PlaysGoodFramesAndNamesEveryDamagedFile) {
  Received got;
  got.subscribe(nh_, "/");
  ASSERT_TRUE(waitFor([&] { return rosout_.has("player: done"); }, deadline_)) << "the player did not finish";
  const size_t kColor = 11, kSemantic = 11, kInstances = 7, kFlow = 6;
  // "done" follows the last publish; wait for every topic's last message.
  waitFor([&] {
    return got.reached({{"/capture/color/image_raw", kColor}, {"/ground_truth/semantic", kSemantic},
                        {"/ground_truth/instance_ids", kInstances}, {"/ground_truth/instances_viper", kInstances},
                        {"/ground_truth/flow/forward", kFlow}, {"/ground_truth/flow/backward", kFlow},
                        {"odom", 11}, {"camera_info", 11}, {"boxes_optical", 8}, {"boxes", 7}});
  }, deadline_);
  std::lock_guard<std::mutex> lock(got.mutex_);

  // Every damaged file is named, each once, and nothing else is an error.
  const std::vector<std::pair<std::string, std::string>> problems = {
      {"train/img/001: no file for frames 2", ""},
      {"train/img/001/README.txt", "name is not"},
      {"cls/001/001_00003.png", "size 32x48 differs from the frame's 64x48"},
      {"flow/001/001_00004.npz", "left out"},
      {"inst/001/001_00005.png", "truncated"},
      {"bb/001/001_00006.csv:2:", "5 values, expected 28"},
      {"camera/001.csv:7:", "'oops"},
      {"camera/001.csv", "no row for frames 6"},
      {"flowbw/001/001_00001.npz", "Not a zip archive"},
      {"cls/002/002_00001.png", "not a PNG"}};
  const auto lines = rosout_.lines();
  for (const auto& [file, what] : problems) {
    size_t n = 0;
    for (const auto& l : lines)
      n += l.level == rosgraph_msgs::Log::ERROR && l.msg.find(file) != std::string::npos &&
           l.msg.find(what) != std::string::npos;
    EXPECT_EQ(n, 1u) << "one error naming " << file << " (" << what << ")";
  }
  EXPECT_EQ(rosout_.errors(), problems.size());
  EXPECT_TRUE(rosout_.has("player: done: 12 frames published, 10 problems reported"));

  // What was published: every frame that has data, with its stamp.
  auto& images = got.images;
  ASSERT_EQ(images["/capture/color/image_raw"].size(), kColor);
  ASSERT_EQ(images["/ground_truth/semantic"].size(), kSemantic);
  ASSERT_EQ(images["/ground_truth/instance_ids"].size(), kInstances);
  ASSERT_EQ(images["/ground_truth/instances_viper"].size(), kInstances);
  ASSERT_EQ(images["/ground_truth/flow/forward"].size(), kFlow);
  ASSERT_EQ(images["/ground_truth/flow/backward"].size(), kFlow);
  ASSERT_EQ(got.odoms.size(), 11u);
  ASSERT_EQ(got.infos.size(), 11u);
  ASSERT_EQ(got.boxes_optical.size(), 8u);
  ASSERT_EQ(got.boxes.size(), 7u);
  // Stamps: frame f of 001 at 1 + f/15 s, 002 follows one frame later.
  const std::vector<uint64_t> color_frames = {0, 1, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  for (size_t i = 0; i < color_frames.size(); ++i) {
    const auto& m = images["/capture/color/image_raw"][i];
    EXPECT_NEAR(m->header.stamp.toSec(), stampOf(color_frames[i]), 1e-6) << "color message " << i;
    EXPECT_EQ(m->encoding, "rgb8");
    EXPECT_EQ(m->header.frame_id, "camera_optical");
  }
  const std::vector<uint64_t> flow_frames = {0, 1, 2, 3, 5, 6}, flowbw_frames = {2, 3, 4, 5, 6, 7};
  for (size_t i = 0; i < kFlow; ++i) {
    EXPECT_NEAR(images["/ground_truth/flow/forward"][i]->header.stamp.toSec(), stampOf(flow_frames[i]), 1e-6);
    EXPECT_NEAR(images["/ground_truth/flow/backward"][i]->header.stamp.toSec(), stampOf(flowbw_frames[i]), 1e-6);
    EXPECT_EQ(images["/ground_truth/flow/forward"][i]->encoding, "32FC2");
  }
  // Pacing at rate 1: the 11 frame intervals take at least most of their 11/15 s.
  const auto& arrival = got.arrival["/capture/color/image_raw"];
  EXPECT_GT((arrival.back() - arrival.front()).toSec(), 0.8 * (stampOf(11) - stampOf(0)));

  // Content.
  EXPECT_EQ(images["/capture/color/image_raw"][0]->data, colorImage(1, 0).data);
  double jpeg_error = 0;
  const auto jpeg = colorImage(1, 7).data;
  for (size_t i = 0; i < jpeg.size(); ++i) jpeg_error += std::abs(int(images["/capture/color/image_raw"][6]->data[i]) - int(jpeg[i]));
  EXPECT_LT(jpeg_error / jpeg.size(), 4.0) << "frame 7 is a JPEG";
  EXPECT_EQ(images["/capture/color/image_raw"][7]->data, colorImage(2, 0).data);
  EXPECT_EQ(images["/ground_truth/semantic"][0]->encoding, "mono8");
  EXPECT_EQ(images["/ground_truth/semantic"][0]->data, classImage(1, 0).data);
  EXPECT_EQ(images["/ground_truth/semantic"][3]->data, viper::dataset::viperInstanceClasses(instanceImage(3)))
      << "frame 3's cls has the wrong size: the classes come from inst's R channel";
  EXPECT_EQ(images["/ground_truth/semantic"][8]->data, classImage(2, 0).data);
  EXPECT_NEAR(images["/ground_truth/semantic"][9]->header.stamp.toSec(), stampOf(10), 1e-6) << "002 frame 1's cls is bad";
  const auto ids = viper::dataset::viperInstanceIds(instanceImage(0));
  EXPECT_EQ(images["/ground_truth/instance_ids"][0]->encoding, "32SC1");
  ASSERT_EQ(images["/ground_truth/instance_ids"][0]->data.size(), ids.size() * 4);
  EXPECT_EQ(std::memcmp(images["/ground_truth/instance_ids"][0]->data.data(), ids.data(), ids.size() * 4), 0);
  EXPECT_EQ(images["/ground_truth/instances_viper"][0]->data, instanceImage(0).data);
  EXPECT_TRUE(sameFloats(*images["/ground_truth/flow/forward"][0], flowImage(0, false).uv)) << "NaN kept, values exact";
  EXPECT_TRUE(sameFloats(*images["/ground_truth/flow/backward"][0], flowImage(2, true).uv));

  // Poses: map = the first camera body frame; 0.5 m forward and 0.02 rad left per frame.
  const std::vector<uint64_t> pose_frames = {0, 1, 2, 3, 4, 5, 7, 0, 1, 2, 3};
  for (size_t i = 0; i < got.odoms.size(); ++i) {
    const auto& o = *got.odoms[i];
    const Eigen::Isometry3d expected = expectedMapFromBody(pose_frames[i]);
    const Eigen::Isometry3d pose = viper::fromPoseMsg(o.pose.pose);
    EXPECT_LT((pose.translation() - expected.translation()).norm(), 1e-6) << "odom " << i;
    EXPECT_LT((pose.linear() - expected.linear()).norm(), 1e-6) << "odom " << i;
    EXPECT_EQ(o.header.frame_id, "map");
    EXPECT_EQ(o.child_frame_id, "camera");
    if (i > 0 && pose_frames[i] > 0) {
      // The camera moves along the world's -Z, not along its heading: seen from the turned body.
      EXPECT_NEAR(o.twist.twist.linear.x, kStepM * 15 * std::cos(kYawRad * pose_frames[i]), 1e-4) << "odom " << i;
      EXPECT_NEAR(o.twist.twist.linear.y, -kStepM * 15 * std::sin(kYawRad * pose_frames[i]), 1e-4) << "odom " << i;
      EXPECT_NEAR(o.twist.twist.angular.z, kYawRad * 15, 1e-3) << "odom " << i;
    }
  }
  // Boxes: the car at (1, 0, 10) in the optical frame, 3 x 1.5 x 6 m; in map through the pose.
  for (size_t i = 0; i < got.boxes_optical.size(); ++i) {
    ASSERT_EQ(got.boxes_optical[i]->boxes.size(), 1u) << "frame " << i << ": frame 6's bad line is skipped";
    const viper::Box3D& b = got.boxes_optical[i]->boxes[0];
    EXPECT_EQ(b.id, kCarId);
    EXPECT_EQ(b.class_id, kCarClass);
    EXPECT_EQ(b.class_name, "car");
    EXPECT_NEAR(b.pose.position.x, 1, 1e-6);
    EXPECT_NEAR(b.pose.position.y, 0, 1e-6);
    EXPECT_NEAR(b.pose.position.z, 10, 1e-6);
    EXPECT_NEAR(b.size.x, 3, 1e-6);
    EXPECT_NEAR(b.size.y, 1.5, 1e-6);
    EXPECT_NEAR(b.size.z, 6, 1e-6);
  }
  const std::vector<uint64_t> box_frames = {0, 1, 2, 3, 4, 5, 7};
  for (size_t i = 0; i < got.boxes.size(); ++i) {
    const Eigen::Vector3d expected = expectedMapFromBody(box_frames[i]) * Eigen::Vector3d(10, -1, 0);
    const auto& p = got.boxes[i]->boxes.at(0).pose.position;
    EXPECT_LT((Eigen::Vector3d(p.x, p.y, p.z) - expected).norm(), 1e-6) << "box in map, frame " << box_frames[i];
    EXPECT_EQ(got.boxes[i]->header.frame_id, "map");
  }
  // camera_info from the projection: 60 degrees vertical field of view, principal point centred.
  const double f = 24.0 / std::tan(M_PI / 6);
  for (const auto& info : got.infos) {
    EXPECT_NEAR(info->K[0], f, 1e-4);
    EXPECT_NEAR(info->K[4], f, 1e-4);
    EXPECT_NEAR(info->K[2], 31.5, 1e-6);
    EXPECT_NEAR(info->K[5], 23.5, 1e-6);
    EXPECT_EQ(info->width, kWidth);
  }
}

TEST_F(ViperLayoutPlayer, LoopsWithIncreasingStampsAndClock) {
  std::mutex mutex;
  std::vector<double> clock;
  ros::Subscriber clock_sub = nh_.subscribe<rosgraph_msgs::Clock>("/clock", 1000, [&](const rosgraph_msgs::ClockConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    clock.push_back(m->clock.toSec());
  });
  Received got;
  got.subscribe(nh_, "/");
  const size_t per_pass = 11;
  ASSERT_TRUE(waitFor([&] { return got.count("/capture/color/image_raw") >= 3 * per_pass; }, deadline_))
      << "three passes of the color topic";
  std::lock_guard<std::mutex> lock(got.mutex_);
  const auto& color = got.images["/capture/color/image_raw"];
  for (size_t i = 1; i < color.size(); ++i)
    ASSERT_GT(color[i]->header.stamp, color[i - 1]->header.stamp) << "stamps never repeat or go back, message " << i;
  // A later pass repeats the images of the first one.
  for (size_t i = 0; i + per_pass < color.size() && i < 2 * per_pass; ++i) {
    // The first messages may have been missed while connecting: compare by content period.
    if (color[i]->data != color[i + per_pass]->data) {
      ADD_FAILURE() << "message " << i << " and " << i + per_pass << " differ";
      break;
    }
  }
  {
    std::lock_guard<std::mutex> l(mutex);
    ASSERT_GE(clock.size(), 2 * per_pass);
    for (size_t i = 1; i < clock.size(); ++i) ASSERT_GT(clock[i], clock[i - 1]) << "/clock " << i;
  }
  EXPECT_EQ(rosout_.errors(), 10u) << "problems are logged on the first pass only";
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "viper_layout_tester");
}
