// Tests of VIPER layout interop with the real nodes; each .test file runs one of them
// (--gtest_filter):
//  - PlaysGoodFramesAndNamesEveryDamagedFile: the player (node or nodelet, started by the .test file) plays
//    make_viper_test_layout's dataset; every damaged file is reported on /rosout naming it, every
//    good frame is published on every topic it has data for, with the right stamps, encodings,
//    content, poses, boxes and camera_info, paced at ~rate;
//  - LoopsWithIncreasingStampsAndClock: the player loops: stamps and /clock keep increasing, problems are logged once;
//  - GroundTruthExportPlayerGiveIdenticalTopics: the committed raw bag through the ground-truth nodelets (replay.launch),
//    recorded into a bag here, export_viper into the layout (the live exporter, in this process,
//    writes the same files from the live topics), the player (in this process) back to
//    topics: images identical, flow identical to float16, poses, boxes and intrinsics equal within
//    float precision; viper_to_bag of the layout gives the player's messages.
// Private parameters: timeout_s (120); the round trip also bag, export_viper, viper_to_bag.
#include "bag_publishers.h"
#include "viper_layout_tester_support.h"
#include "../common/process_util.h"
#include "viper_test_layout.h"

#include "viper/ground_truth/ego_motion.h"
#include "viper/dataset/float16.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/dataset/live_exporter.h"
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

TEST(ViperLayoutPlayer, PlaysGoodFramesAndNamesEveryDamagedFile) {
  ros::NodeHandle nh, pnh("~");
  const double timeout_s = pnh.param("timeout_s", 120.0);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);

  // /rosout first, so no problem the player logs once it has subscribers is missed.
  Rosout rosout(nh);
  ASSERT_TRUE(waitFor([&] { return rosout.publishers() >= 2; }, deadline)) << "the player never connected to /rosout";
  Received got;
  got.subscribe(nh, "/");
  ASSERT_TRUE(waitFor([&] { return rosout.has("player: done"); }, deadline)) << "the player did not finish";
  const size_t kColor = 11, kSemantic = 11, kInstances = 7, kFlow = 6;
  waitFor([&] { return got.count("/capture/color/image_raw") >= kColor && got.count("/ground_truth/flow/backward") >= kFlow; },
          ros::WallTime::now() + ros::WallDuration(10));
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
  const auto lines = rosout.lines();
  for (const auto& [file, what] : problems) {
    size_t n = 0;
    for (const auto& l : lines)
      n += l.level == rosgraph_msgs::Log::ERROR && l.msg.find(file) != std::string::npos &&
           l.msg.find(what) != std::string::npos;
    EXPECT_EQ(n, 1u) << "one error naming " << file << " (" << what << ")";
  }
  EXPECT_EQ(rosout.errors(), problems.size());
  EXPECT_TRUE(rosout.has("player: done: 12 frames published, 10 problems reported"));

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

TEST(ViperLayoutPlayer, LoopsWithIncreasingStampsAndClock) {
  ros::NodeHandle nh, pnh("~");
  const double timeout_s = pnh.param("timeout_s", 120.0);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  Rosout rosout(nh);
  ASSERT_TRUE(waitFor([&] { return rosout.publishers() >= 2; }, deadline));
  std::mutex mutex;
  std::vector<double> clock;
  ros::Subscriber clock_sub = nh.subscribe<rosgraph_msgs::Clock>("/clock", 1000, [&](const rosgraph_msgs::ClockConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    clock.push_back(m->clock.toSec());
  });
  Received got;
  got.subscribe(nh, "/");
  const size_t per_pass = 11;
  ASSERT_TRUE(waitFor([&] { return got.count("/capture/color/image_raw") >= 3 * per_pass; }, deadline))
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
  EXPECT_EQ(rosout.errors(), 10u) << "problems are logged on the first pass only";
}

// ---- round trip ----------------------------------------------------------------------------

// The ground truth of the raw bag, as the nodes published it, by topic, in order.
struct Truth {
  std::mutex mutex;
  std::map<std::string, std::vector<topic_tools::ShapeShifter::ConstPtr>> messages;
  size_t count(const std::string& t) {
    std::lock_guard<std::mutex> lock(mutex);
    return messages[t].size();
  }
};

template <typename M>
boost::shared_ptr<const M> as(const topic_tools::ShapeShifter::ConstPtr& s) {
  return s->instantiate<M>();
}

Eigen::Isometry3d poseOf(const nav_msgs::Odometry& o) { return viper::fromPoseMsg(o.pose.pose); }

// The messages of `topic` in `bag` equal those received live, in order (header.seq aside).
template <typename M>
void expectSameMessages(rosbag::Bag& bag, std::map<std::string, std::vector<topic_tools::ShapeShifter::ConstPtr>>& truth,
                        const std::string& topic) {
  std::vector<boost::shared_ptr<M>> got;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) got.push_back(m.instantiate<M>());
  const auto& expected = truth[topic];
  ASSERT_EQ(got.size(), expected.size()) << topic;
  for (size_t i = 0; i < got.size(); ++i) {
    boost::shared_ptr<M> want = expected[i]->instantiate<M>();
    ASSERT_TRUE(got[i] && want) << topic << " " << i;
    got[i]->header.seq = want->header.seq = 0;
    EXPECT_TRUE(*got[i] == *want) << topic << " message " << i << " differs";
  }
}

TEST(ViperLayoutRoundTrip, GroundTruthExportPlayerGiveIdenticalTopics) {
  ros::NodeHandle nh, pnh("~");
  const double timeout_s = pnh.param("timeout_s", 120.0);
  std::string bag_path, export_viper, viper_to_bag, generate, label_table;
  ASSERT_TRUE(pnh.getParam("bag", bag_path));
  ASSERT_TRUE(pnh.getParam("export_viper", export_viper));
  ASSERT_TRUE(pnh.getParam("viper_to_bag", viper_to_bag));
  ASSERT_TRUE(pnh.getParam("generate", generate));
  ASSERT_TRUE(pnh.getParam("label_table", label_table));
  ros::AsyncSpinner spinner(3);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  std::string work_template = (fs::temp_directory_path() / "viper_roundtrip_XXXXXX").string();
  ASSERT_NE(mkdtemp(work_template.data()), nullptr);
  const fs::path work = work_template;

  // 1. The raw bag through the ground-truth nodes, frame by frame; everything they say is kept.
  const std::vector<std::string> outputs = {"/ground_truth/semantic",       "/ground_truth/instance_ids",
                                            "/ground_truth/instances_viper", "/ground_truth/flow/forward",
                                            "/ground_truth/flow/backward",   "/ground_truth/odom",
                                            "/ground_truth/boxes_optical",   "/ground_truth/objects"};
  Truth truth;
  std::vector<ros::Subscriber> subs;
  for (const std::string& t : outputs)
    subs.push_back(nh.subscribe<topic_tools::ShapeShifter>(t, 200, [&truth, t](const topic_tools::ShapeShifter::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(truth.mutex);
      truth.messages[t].push_back(m);
    }));
  // The live exporter (viper_exporter's class, in this process) writes the same topics as they come.
  ros::NodeHandle live_pnh("~live_exporter");
  live_pnh.setParam("root", (work / "live").string());
  viper::LiveExporter live(nh, live_pnh);
  ASSERT_TRUE(live.start());
  rosbag::Bag raw(bag_path, rosbag::bagmode::Read);
  rosbag::View view(raw);
  std::map<std::string, ros::Publisher> pubs = viper::test::advertiseBagTopics(nh, view);
  auto connected = [&] {
    if (pubs["/capture/draws"].getNumSubscribers() < 1 || pubs["/capture/draw_ids"].getNumSubscribers() < 1) return false;
    // the manager of instances, boxes and flow takes the mesh store (see below)
    if (pubs.count("/capture/mesh_store") && pubs["/capture/mesh_store"].getNumSubscribers() < 1) return false;
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return false;
    return live.inputsConnected();
  };
  ASSERT_TRUE(waitFor(connected, deadline)) << "ground-truth nodes did not connect";
  std::vector<ros::Time> frames;
  std::map<std::string, std::vector<rosbag::MessageInstance>> raw_messages;
  // Each node takes the mesh store on a callback of its own, which may run after the frame's (then
  // its boxes lack the meshes): the live pipeline's race, which generate (lockstep) has not. So a
  // mesh store goes out before every other message of its time, and the nodes get time to take it.
  std::deque<rosbag::MessageInstance> mesh_stores;
  for (const rosbag::MessageInstance& m : rosbag::View(raw, rosbag::TopicQuery("/capture/mesh_store")))
    mesh_stores.push_back(m);
  auto publish = [&](const rosbag::MessageInstance& m) {
    raw_messages[m.getTopic()].push_back(m);
    pubs[m.getTopic()].publish(m.instantiate<topic_tools::ShapeShifter>());
  };
  for (const rosbag::MessageInstance& m : view) {
    if (m.getTopic() == "/capture/mesh_store") continue;
    while (!mesh_stores.empty() && mesh_stores.front().getTime() <= m.getTime()) {
      publish(mesh_stores.front());
      mesh_stores.pop_front();
      ros::WallDuration(0.5).sleep();
    }
    if (m.getTopic() == "/capture/draws") {
      waitFor([&] { return truth.count("/ground_truth/odom") >= frames.size(); }, deadline);
      frames.push_back(m.instantiate<viper::DrawList>()->header.stamp);
    }
    publish(m);
  }
  const size_t n = frames.size();
  ASSERT_GE(n, 10u);
  for (const std::string& t : outputs) {
    const size_t expected = t.find("/flow/") != std::string::npos ? n - 1 : n;
    ASSERT_TRUE(waitFor([&] { return truth.count(t) >= expected; }, deadline)) << t << ": " << truth.count(t) << " of " << expected;
  }

  // 2. Recorded into a ground-truth bag, as replay.launch's record:= would.
  const std::string gt_bag = (work / "gt.bag").string();
  {
    std::lock_guard<std::mutex> lock(truth.mutex);
    rosbag::Bag out(gt_bag, rosbag::bagmode::Write);
    for (const char* t : {"/capture/color/image_raw", "/capture/color/camera_info", "/capture/draws"})
      for (const auto& m : raw_messages[t]) out.write(t, m.getTime(), m);
    for (const auto& [t, messages] : truth.messages)
      for (const auto& m : messages) out.write(t, ros::Time::now(), m);
  }

  // 3. export_viper into the layout.
  const fs::path layout = work / "layout";
  ASSERT_EQ(run(export_viper + " --bag " + gt_bag + " --out " + layout.string() + " > " + (work / "export.log").string() + " 2>&1"), 0)
      << "export_viper failed; see " << (work / "export.log");
  for (const char* m : {"img", "cls", "inst", "flow", "flowbw", "bb"})
    EXPECT_TRUE(fs::is_directory(layout / "train" / m / "001")) << m;
  EXPECT_TRUE(fs::is_regular_file(layout / "train" / "camera" / "001.csv"));

  // 3b. The live export is the bag export, file for file and byte for byte.
  const std::vector<std::string> live_topics = {"/ground_truth/semantic",   "/ground_truth/instance_ids",
                                                "/ground_truth/instances_viper", "/ground_truth/flow/forward",
                                                "/ground_truth/flow/backward",  "/ground_truth/boxes_optical",
                                                "/ground_truth/objects"};
  size_t expected_live = 2 * n;  // color and draws
  for (const std::string& t : live_topics) expected_live += truth.count(t);
  EXPECT_TRUE(waitFor([&] { return live.messagesReceived() >= expected_live; }, deadline))
      << "the live exporter received " << live.messagesReceived() << " of " << expected_live << " messages";
  EXPECT_EQ(live.finish(), 0) << live.summary();
  EXPECT_EQ(live.framesNumbered(), n);
  expectSameTree(layout, work / "live");

  // 3c. generate: the same raw bag in lockstep, without the nodes: the same ground truth, message
  // for message (header.seq aside: a publisher's count), and the same layout, byte for byte.
  const fs::path generated = work / "generated";
  ASSERT_EQ(run(generate + " --input " + bag_path + " --labels " + label_table + " --out " + generated.string() + " > " +
                (work / "generate.log").string() + " 2>&1"),
            0)
      << "generate failed; see " << (work / "generate.log");
  {
    std::lock_guard<std::mutex> lock(truth.mutex);
    rosbag::Bag gen((generated / "train" / "bag" / "001.bag").string(), rosbag::bagmode::Read);
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/semantic");
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/instance_ids");
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/instances_viper");
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/flow/forward");
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/flow/backward");
    expectSameMessages<nav_msgs::Odometry>(gen, truth.messages, "/ground_truth/odom");
    expectSameMessages<viper::Box3DArray>(gen, truth.messages, "/ground_truth/boxes_optical");
    expectSameMessages<viper::ObjectArray>(gen, truth.messages, "/ground_truth/objects");
  }
  expectSameTree(layout, generated, [](const std::string& rel) {
    return rel.rfind("train/bag/", 0) == 0 || rel == "train/001.done";  // generate's own outputs
  });
  EXPECT_EQ(run(generate + " --input " + bag_path + " --labels " + label_table + " --out " + generated.string() +
                " > " + (work / "generate_again.log").string() + " 2>&1"),
            0);
  EXPECT_NE(viper::test::readFile((work / "generate_again.log").string()).find("is finished"), std::string::npos)
      << "a finished sequence is not generated again";

  // 4. The player, in this process, under /replayed.
  ros::NodeHandle replayed("replayed"), player_pnh("~player");
  player_pnh.setParam("root", layout.string());
  player_pnh.setParam("rate", 0.0);
  player_pnh.setParam("wait_for_subscribers", true);
  player_pnh.setParam("publish_clock", false);
  Received got;
  got.subscribe(replayed, "/replayed/");
  viper::Player player(replayed, player_pnh);
  ASSERT_TRUE(player.start(false));
  ASSERT_TRUE(waitFor([&] { return player.done(); }, deadline)) << "the player did not finish";
  ASSERT_TRUE(waitFor([&] { return got.count("/replayed/ground_truth/flow/backward") >= n - 1 &&
                                   got.count("/replayed/capture/color/image_raw") >= n; }, deadline));
  EXPECT_EQ(player.problemsReported(), 0u);
  EXPECT_EQ(player.framesPublished(), n);

  // 5. The same topics: images identical, flow identical to float16, poses and boxes equal.
  std::lock_guard<std::mutex> lock_truth(truth.mutex);
  std::lock_guard<std::mutex> lock_got(got.mutex_);
  auto images = [&](const std::string& t) { return got.images["/replayed/" + t]; };
  ASSERT_EQ(images("capture/color/image_raw").size(), n);
  for (size_t i = 0; i < n; ++i) {
    const auto original = raw_messages["/capture/color/image_raw"][i].instantiate<sensor_msgs::Image>();
    EXPECT_EQ(images("capture/color/image_raw")[i]->data, original->data) << "color " << i;
  }
  for (const char* t : {"semantic", "instance_ids", "instances_viper"}) {
    const auto& original = truth.messages[std::string("/ground_truth/") + t];
    const auto replayed_images = images(std::string("ground_truth/") + t);
    ASSERT_EQ(replayed_images.size(), original.size()) << t;
    for (size_t i = 0; i < original.size(); ++i) {
      const auto o = as<sensor_msgs::Image>(original[i]);
      EXPECT_EQ(replayed_images[i]->encoding, o->encoding) << t;
      EXPECT_EQ(replayed_images[i]->data, o->data) << t << " " << i;
    }
  }
  for (const char* t : {"flow/forward", "flow/backward"}) {
    const auto& original = truth.messages[std::string("/ground_truth/") + t];
    const auto replayed_images = images(std::string("ground_truth/") + t);
    ASSERT_EQ(replayed_images.size(), original.size()) << t;
    for (size_t i = 0; i < original.size(); ++i) {
      const auto o = as<sensor_msgs::Image>(original[i]);
      std::vector<float> halves(o->data.size() / 4);
      std::memcpy(halves.data(), o->data.data(), o->data.size());
      for (float& v : halves) v = viper::dataset::halfToFloat(viper::dataset::floatToHalf(v));
      EXPECT_TRUE(sameFloats(*replayed_images[i], halves)) << t << " " << i << ": the original rounded to float16";
    }
  }
  const auto& odom = truth.messages["/ground_truth/odom"];
  ASSERT_EQ(got.odoms.size(), odom.size());
  const Eigen::Isometry3d origin = poseOf(*as<nav_msgs::Odometry>(odom[0])).inverse();
  double pose_error = 0;
  for (size_t i = 0; i < odom.size(); ++i) {
    const Eigen::Isometry3d expected = origin * poseOf(*as<nav_msgs::Odometry>(odom[i]));
    const Eigen::Isometry3d replayed_pose = poseOf(*got.odoms[i]);
    pose_error = std::max(pose_error, (expected.matrix() - replayed_pose.matrix()).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(pose_error, 1e-4) << "poses relative to the first frame (float32 view matrices)";
  const auto& boxes = truth.messages["/ground_truth/boxes_optical"];
  ASSERT_EQ(got.boxes_optical.size(), boxes.size());
  size_t box_count = 0;
  for (size_t i = 0; i < boxes.size(); ++i) {
    const auto o = as<viper::Box3DArray>(boxes[i]);
    ASSERT_EQ(got.boxes_optical[i]->boxes.size(), o->boxes.size()) << "frame " << i;
    for (size_t k = 0; k < o->boxes.size(); ++k, ++box_count) {
      const viper::Box3D &a = o->boxes[k], &b = got.boxes_optical[i]->boxes[k];
      EXPECT_EQ(a.id, b.id);
      EXPECT_EQ(a.class_id, b.class_id);
      EXPECT_EQ(a.class_name, b.class_name);
      const Eigen::Isometry3d pa = viper::fromPoseMsg(a.pose), pb = viper::fromPoseMsg(b.pose);
      EXPECT_LT((pa.matrix() - pb.matrix()).cwiseAbs().maxCoeff(), 1e-5) << "box " << a.id << " frame " << i;
      EXPECT_NEAR(a.size.x, b.size.x, 1e-5);
      EXPECT_NEAR(a.size.y, b.size.y, 1e-5);
      EXPECT_NEAR(a.size.z, b.size.z, 1e-5);
    }
  }
  EXPECT_GT(box_count, n) << "the test scene has several boxes per frame";
  {
    std::set<int64_t> ids;
    std::map<std::string, size_t> classes;
    for (const auto& b : boxes) {
      const auto frame_boxes = as<viper::Box3DArray>(b);
      for (const viper::Box3D& box : frame_boxes->boxes) ids.insert(box.id), ++classes[box.class_name];
    }
    std::cout << "round trip: " << n << " frames, " << box_count << " boxes of " << ids.size() << " tracks:";
    for (const auto& [name, count] : classes) std::cout << " " << name << " " << count;
    std::cout << std::endl;
  }
  const auto& infos = raw_messages["/capture/color/camera_info"];
  ASSERT_EQ(got.infos.size(), infos.size());
  for (size_t i = 0; i < infos.size(); ++i) {
    const auto o = infos[i].instantiate<sensor_msgs::CameraInfo>();
    for (int k = 0; k < 9; ++k) EXPECT_NEAR(got.infos[i]->K[k], o->K[k], 1e-3) << "K[" << k << "] of frame " << i;
  }

  // 6. viper_to_bag of the layout holds the player's messages.
  const std::string out_bag = (work / "layout.bag").string();
  ASSERT_EQ(run(viper_to_bag + " --root " + layout.string() + " --out " + out_bag + " > " + (work / "to_bag.log").string() + " 2>&1"), 0)
      << "viper_to_bag failed; see " << (work / "to_bag.log");
  rosbag::Bag converted(out_bag, rosbag::bagmode::Read);
  for (const char* t : kImageTopics) {
    rosbag::View v(converted, rosbag::TopicQuery(std::string("/") + t));
    const auto replayed_images = images(t);
    ASSERT_EQ(v.size(), replayed_images.size()) << t;
    size_t i = 0;
    for (const rosbag::MessageInstance& m : v) {
      const auto image = m.instantiate<sensor_msgs::Image>();
      EXPECT_EQ(image->header.stamp, replayed_images[i]->header.stamp) << t << " " << i;
      EXPECT_EQ(m.getTime(), image->header.stamp);
      EXPECT_EQ(image->data, replayed_images[i]->data) << t << " " << i;
      ++i;
    }
  }
  rosbag::View v(converted, rosbag::TopicQuery("/ground_truth/odom"));
  ASSERT_EQ(v.size(), got.odoms.size());
  size_t i = 0;
  for (const rosbag::MessageInstance& m : v) {
    const auto o = m.instantiate<nav_msgs::Odometry>();
    EXPECT_EQ(o->pose.pose.position.x, got.odoms[i]->pose.pose.position.x);
    EXPECT_EQ(o->twist.twist.linear.x, got.odoms[i]->twist.twist.linear.x);
    ++i;
  }
  EXPECT_EQ(rosbag::View(converted, rosbag::TopicQuery("/tf")).size(), n);
  EXPECT_EQ(rosbag::View(converted, rosbag::TopicQuery("/tf_static")).size(), 1u);
  player.stop();
  if (!HasFailure()) fs::remove_all(work);  // kept for a look otherwise
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "viper_layout_tester");
  return RUN_ALL_TESTS();
}
