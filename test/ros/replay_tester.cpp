// Replays a raw bag into the ground-truth nodes and checks, frame by frame, that every raw and
// ground-truth topic arrives with the frame's stamp, and that tracked objects keep their ids.
// The tester publishes the bag itself (rosbag API) so it can start once every node is connected and
// send a frame only after the previous one came out: conditions, not sleeps.
// Private parameters: bag (path, required), timeout_s (60).
#include "tester_main.h"
#include "bag_publishers.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <topic_tools/shape_shifter.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <map>
#include <mutex>
#include <set>

namespace {

const std::vector<std::string> kOutputs = {"/ground_truth/semantic", "/ground_truth/instance_ids",
                                           "/ground_truth/objects", "/ground_truth/boxes", "/ground_truth/odom",
                                           "/ground_truth/semantic_overlay"};

class ReplayTest : public ::testing::Test {
 protected:
  std::mutex mutex_;
  std::map<std::string, std::vector<ros::Time>> stamps_;
  std::map<int32_t, std::set<uint8_t>> classes_of_track_;
  std::vector<std::set<int32_t>> cars_per_frame_;
  std::set<uint8_t> semantic_classes_;

  void got(const std::string& topic, const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    stamps_[topic].push_back(stamp);
  }
  size_t count(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    return stamps_[topic].size();
  }
};

TEST_F(ReplayTest, EveryFrameComesOutOfEveryNodeWithItsStamp) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  double timeout_s = 60;
  pnh.param("timeout_s", timeout_s, 60.0);

  std::vector<ros::Subscriber> subs;
  subs.push_back(nh.subscribe<sensor_msgs::Image>(kOutputs[0], 50, [this](const sensor_msgs::ImageConstPtr& m) {
    got(kOutputs[0], m->header.stamp);
    std::lock_guard<std::mutex> lock(mutex_);
    semantic_classes_.insert(m->data.begin(), m->data.end());
  }));
  subs.push_back(nh.subscribe<sensor_msgs::Image>(kOutputs[1], 50, [this](const sensor_msgs::ImageConstPtr& m) {
    got(kOutputs[1], m->header.stamp);
  }));
  subs.push_back(nh.subscribe<viper::ObjectArray>(kOutputs[2], 50, [this](const viper::ObjectArrayConstPtr& m) {
    got(kOutputs[2], m->header.stamp);
    std::lock_guard<std::mutex> lock(mutex_);
    std::set<int32_t> cars;
    for (const auto& o : m->objects) {
      if (o.track_id > 0) classes_of_track_[o.track_id].insert(o.class_id);
      if (o.class_id == 24 && o.pixel_count > 0) cars.insert(o.track_id);
    }
    cars_per_frame_.push_back(cars);
  }));
  subs.push_back(nh.subscribe<viper::Box3DArray>(kOutputs[3], 50, [this](const viper::Box3DArrayConstPtr& m) {
    got(kOutputs[3], m->header.stamp);
  }));
  subs.push_back(nh.subscribe<nav_msgs::Odometry>(kOutputs[4], 50, [this](const nav_msgs::OdometryConstPtr& m) {
    got(kOutputs[4], m->header.stamp);
  }));
  subs.push_back(nh.subscribe<sensor_msgs::Image>(kOutputs[5], 50, [this](const sensor_msgs::ImageConstPtr& m) {
    got(kOutputs[5], m->header.stamp);
  }));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, ros::Publisher> pubs = viper::test::advertiseBagTopics(nh, view);
  ASSERT_TRUE(pubs.count("/capture/draws")) << bag_path << " has no /capture/draws";

  // Start once every output reaches us (each node advertises, then subscribes, in its start())
  // and the nodes' process is connected to the raw topics (nodelets of one manager share one
  // connection per topic).
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  auto connected = [&] {
    if (pubs["/capture/draws"].getNumSubscribers() < 1 || pubs["/capture/draw_ids"].getNumSubscribers() < 1) return false;
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return false;
    return true;
  };
  while (!connected() && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  if (!connected()) {
    std::string state = "draws subscribers " + std::to_string(pubs["/capture/draws"].getNumSubscribers()) +
                        ", draw_ids subscribers " + std::to_string(pubs["/capture/draw_ids"].getNumSubscribers());
    for (const auto& s : subs) state += ", " + s.getTopic() + " publishers " + std::to_string(s.getNumPublishers());
    FAIL() << "ground-truth nodes did not connect within " << timeout_s << " s: " << state;
  }

  std::vector<ros::Time> frames;
  for (const rosbag::MessageInstance& m : view) {
    const bool is_draws = m.getTopic() == "/capture/draws";
    if (is_draws) {
      // Each frame's messages start with its draw list only after the previous frame came out.
      while (count("/ground_truth/odom") < frames.size() && ros::WallTime::now() < deadline)
        ros::WallDuration(0.005).sleep();
      frames.push_back(m.instantiate<viper::DrawList>()->header.stamp);
    }
    pubs[m.getTopic()].publish(m.instantiate<topic_tools::ShapeShifter>());
  }
  ASSERT_GE(frames.size(), 10u);
  for (const auto& t : kOutputs) {
    while (count(t) < frames.size() && ros::WallTime::now() < deadline) ros::WallDuration(0.01).sleep();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& t : kOutputs) EXPECT_EQ(stamps_[t], frames) << t << ": every frame, in order, with its stamp";
  EXPECT_TRUE(semantic_classes_.count(24) && semantic_classes_.count(3)) << "cars and road in the semantic image";
  for (const auto& [id, classes] : classes_of_track_) EXPECT_EQ(classes.size(), 1u) << "track " << id << " changed class";
  // No identity switch: the cars seen over the replay are as many as the most seen in one frame.
  std::set<int32_t> all_cars;
  size_t most = 0;
  for (const auto& c : cars_per_frame_) all_cars.insert(c.begin(), c.end()), most = std::max(most, c.size());
  EXPECT_GE(most, 1u);
  EXPECT_EQ(all_cars.size(), most) << "car track ids changed during the replay";
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "replay_tester");
}
