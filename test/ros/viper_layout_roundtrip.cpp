// The round trip test of viper_layout_tester (its main is in viper_layout_tester.cpp): a raw bag
// through the ground-truth nodes, recorded, exported (export_viper, and the live exporter in this
// process), played back by the player and converted by viper_to_bag, and generated in lockstep by
// generate: every topic and every file compared. Private parameters: bag, export_viper,
// viper_to_bag, generate, label_table, timeout_s (120).
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
#include <sensor_msgs/PointCloud2.h>
#include <topic_tools/shape_shifter.h>
#include <viper/AmodalInstanceArray.h>
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
                                            "/ground_truth/boxes_optical",   "/ground_truth/objects",
                                            // the modalities beyond VIPER's (generate --modalities all)
                                            "/ground_truth/normals",         "/ground_truth/labelled_cloud",
                                            "/ground_truth/flow/scene_flow", "/ground_truth/amodal/objects"};
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
  viper::ViperExporterNode live(nh, live_pnh);
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
  // The normals, labelled_cloud and amodal nodes (and the flow node's scene flow) take their inputs
  // only once their outputs have a subscriber, which the connections above do not show (the manager
  // already takes those topics for the other nodes): under load the first frame came before the
  // cloud's inputs were taken (19 of 20 clouds). Time for them to subscribe.
  ros::WallDuration(2.0).sleep();
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
  ASSERT_EQ(run(generate + " --input " + bag_path + " --labels " + label_table + " --out " + generated.string() +
                " --modalities all > " +
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
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/normals");
    expectSameMessages<sensor_msgs::PointCloud2>(gen, truth.messages, "/ground_truth/labelled_cloud");
    expectSameMessages<sensor_msgs::Image>(gen, truth.messages, "/ground_truth/flow/scene_flow");
    expectSameMessages<viper::AmodalInstanceArray>(gen, truth.messages, "/ground_truth/amodal/objects");
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
  std::map<std::string, size_t> counts = {{"/replayed/capture/color/image_raw", n}};
  {
    std::lock_guard<std::mutex> lock(truth.mutex);
    counts["odom"] = truth.messages["/ground_truth/odom"].size();
    counts["boxes_optical"] = truth.messages["/ground_truth/boxes_optical"].size();
    for (const char* t : {"semantic", "instance_ids", "instances_viper", "flow/forward", "flow/backward"})
      counts[std::string("/replayed/ground_truth/") + t] = truth.messages[std::string("/ground_truth/") + t].size();
  }
  ASSERT_TRUE(waitFor([&] { return got.reached(counts); }, deadline)) << "the replayed topics did not all arrive";
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
