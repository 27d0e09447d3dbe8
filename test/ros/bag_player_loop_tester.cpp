// rostest tester for bag_player with ~loop: the bag's draw lists arrive pass after pass, each pass
// the bag's own messages but for their header stamps (and sequence numbers), which keep increasing across the start-over
// (the next pass begins one mean frame interval after the last stamp), shifted alike on every
// per-frame topic (the color images carry the draw lists' stamps); /clock never goes back
// (BagPlayerLoop.Passes*). On a bag with /tf (BagPlayerLoop.Tf*, with /use_sim_time): the
// transforms' stamps are shifted with /clock on every pass, a tf2 listener sees no
// TF_REPEATED_DATA and finds the transform at the current time on the third pass, and /tf_static
// stays latched.
//
// Private parameters: bag (path, required), passes (2; the tf test: 3), timeout_s (90).
#include "tester_main.h"

#include <console_bridge/console.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/transform_listener.h>
#include <viper/DrawList.h>

#include <cmath>
#include <functional>
#include <mutex>
#include <set>
#include <vector>

namespace {

using Bytes = std::vector<uint8_t>;

// The message's bytes with its header stamp and sequence number zeroed (a publisher numbers its
// messages on: the second pass's carry on from the first's).
Bytes withoutStamp(viper::DrawList m) {
  m.header.stamp = ros::Time();
  m.header.seq = 0;
  Bytes out(ros::serialization::serializationLength(m));
  ros::serialization::OStream stream(out.data(), static_cast<uint32_t>(out.size()));
  ros::serialization::serialize(stream, m);
  return out;
}

using viper::test::waitFor;

TEST(BagPlayerLoop, PassesRepeatTheBagWithStampsThatKeepIncreasing) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  const int passes = pnh.param("passes", 2);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout_s", 90.0));

  std::vector<viper::DrawList> expected;
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/capture/draws")))
      expected.push_back(*m.instantiate<viper::DrawList>());
  }
  const size_t n = expected.size();
  ASSERT_GE(n, 3u);
  const double bag_interval = (expected.back().header.stamp - expected.front().header.stamp).toSec() / (n - 1);

  std::mutex mutex;
  std::vector<viper::DrawList> draws;
  std::set<ros::Time> image_stamps;
  bool clock_went_back = false;
  ros::Time last_clock;
  auto draws_sub = nh.subscribe<viper::DrawList>("/capture/draws", 1000, [&](const viper::DrawList::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    draws.push_back(*m);
  });
  auto images_sub =
      nh.subscribe<sensor_msgs::Image>("/capture/color/image_raw", 1000, [&](const sensor_msgs::Image::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        image_stamps.insert(m->header.stamp);
      });
  auto clock_sub = nh.subscribe<rosgraph_msgs::Clock>("/clock", 1000, [&](const rosgraph_msgs::Clock::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    clock_went_back = clock_went_back || m->clock < last_clock;
    last_clock = m->clock;
  });
  ros::AsyncSpinner spinner(3);
  spinner.start();
  ASSERT_TRUE(waitFor([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return draws.size() >= passes * n + 1;
  }, deadline)) << "fewer than " << passes * n + 1 << " draw lists (" << passes << " passes of " << n << ")";
  // The images come on connections of their own: wait for those of the passes' frames.
  ASSERT_TRUE(waitFor([&] {
    std::lock_guard<std::mutex> lock(mutex);
    for (size_t i = 0; i < passes * n; ++i)
      if (!image_stamps.count(draws[i].header.stamp)) return false;
    return true;
  }, deadline)) << "no color image for some draw list of the first " << passes << " passes";

  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_FALSE(clock_went_back) << "/clock went back";
  for (size_t i = 1; i < draws.size(); ++i)
    ASSERT_GT(draws[i].header.stamp, draws[i - 1].header.stamp) << "draw list " << i << " of pass " << i / n + 1;
  for (size_t i = 0; i < passes * n; ++i) {
    SCOPED_TRACE("draw list " + std::to_string(i % n) + " of pass " + std::to_string(i / n + 1));
    EXPECT_TRUE(withoutStamp(draws[i]) == withoutStamp(expected[i % n])) << "not the bag's message";
    // Every pass is the first shifted by one amount.
    const double shift = (draws[i].header.stamp - expected[i % n].header.stamp).toSec();
    const double pass_shift = (draws[i - i % n].header.stamp - expected[0].header.stamp).toSec();
    EXPECT_NEAR(shift, pass_shift, 1e-6);
    EXPECT_EQ(image_stamps.count(draws[i].header.stamp), 1u) << "no color image with the draw list's stamp";
  }
  // The next pass starts one mean frame interval after the last stamp.
  const double gap = (draws[n].header.stamp - draws[n - 1].header.stamp).toSec();
  EXPECT_NEAR(gap, bag_interval, 1e-3 + 0.01 * bag_interval);
  std::cout << "bag_player loop: " << draws.size() << " draw lists over " << passes << "+ passes of " << n
            << "; pass 2 starts " << gap << " s after pass 1's last stamp (frame interval " << bag_interval << " s)\n";
}

// console_bridge's messages, where tf2 writes its warnings (TF_REPEATED_DATA among them).
class ConsoleMessages : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel, const char*, int) override {
    std::lock_guard<std::mutex> lock(mutex_);
    texts_.push_back(text);
    std::cerr << "console_bridge: " << text << "\n";
  }
  std::vector<std::string> containing(const std::string& part) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const std::string& t : texts_)
      if (t.find(part) != std::string::npos) out.push_back(t);
    return out;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> texts_;
};

TEST(BagPlayerLoop, TfStampsFollowTheClockOnEveryPass) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  ASSERT_TRUE(ros::Time::isSimTime()) << "run with /use_sim_time: the lookup is at the player's /clock";
  const int passes = pnh.param("passes", 3);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout_s", 90.0));

  // The bag's transforms of its first /tf frame pair, and its static child frame.
  std::vector<ros::Time> bag_stamps;
  std::string parent, child, static_parent, static_child;
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/tf"))) {
      const tf2_msgs::TFMessage::ConstPtr tf = m.instantiate<tf2_msgs::TFMessage>();
      for (const auto& t : tf->transforms) {
        if (parent.empty()) parent = t.header.frame_id, child = t.child_frame_id;
        if (t.child_frame_id == child) bag_stamps.push_back(t.header.stamp);
      }
    }
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/tf_static"))) {
      const tf2_msgs::TFMessage::ConstPtr tf = m.instantiate<tf2_msgs::TFMessage>();
      for (const auto& t : tf->transforms) static_parent = t.header.frame_id, static_child = t.child_frame_id;
    }
  }
  const size_t n = bag_stamps.size();
  ASSERT_GE(n, 3u) << "the bag needs /tf";
  ASSERT_FALSE(static_child.empty()) << "the bag needs /tf_static";
  // Pass k (from 1) is the bag `(k - 1) * step` later (step: the span and one mean interval).
  const double span = (bag_stamps.back() - bag_stamps.front()).toSec(), step = span + span / (n - 1);
  const auto passOf = [&](const ros::Time& t) {
    return 1 + static_cast<int>(std::floor(((t - bag_stamps.front()).toSec() + 1e-6) / step));
  };
  // True when t is a stamp of the bag, shifted as its pass is.
  const auto bagStampShifted = [&](const ros::Time& t) {
    const double unshifted = (t - bag_stamps.front()).toSec() - (passOf(t) - 1) * step;
    for (const ros::Time& b : bag_stamps)
      if (std::abs((b - bag_stamps.front()).toSec() - unshifted) < 1e-6) return true;
    return false;
  };

  ConsoleMessages console;
  console_bridge::useOutputHandler(&console);
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  std::mutex mutex;
  std::vector<ros::Time> tf_stamps, clocks;
  auto tf_sub = nh.subscribe<tf2_msgs::TFMessage>("/tf", 1000, [&](const tf2_msgs::TFMessage::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& t : m->transforms)
      if (t.child_frame_id == child) tf_stamps.push_back(t.header.stamp);
  });
  auto clock_sub = nh.subscribe<rosgraph_msgs::Clock>("/clock", 1000, [&](const rosgraph_msgs::Clock::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    clocks.push_back(m->clock);
  });
  ros::AsyncSpinner spinner(2);
  spinner.start();

  // On the third pass (or later) the transform is there at the current time.
  ros::Time looked_up_at;
  std::string error;
  ASSERT_TRUE(waitFor([&] {
    const ros::Time now = ros::Time::now();
    if (passOf(now) < passes) return false;
    error.clear();
    if (!buffer.canTransform(parent, child, now, &error)) return false;
    looked_up_at = now;
    return true;
  }, deadline)) << "no tf " << parent << " -> " << child << " at the current time on pass " << passes
                << " (/clock " << ros::Time::now() << "): " << error;
  EXPECT_TRUE(buffer.canTransform(parent, static_child, looked_up_at)) << "the static " << static_parent << " -> "
                                                                        << static_child << " is missing";
  // A late subscriber still gets /tf_static: it is latched.
  std::mutex static_mutex;
  std::set<std::string> static_children;
  auto static_sub = nh.subscribe<tf2_msgs::TFMessage>("/tf_static", 10, [&](const tf2_msgs::TFMessage::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(static_mutex);
    for (const auto& t : m->transforms) static_children.insert(t.child_frame_id);
  });
  EXPECT_TRUE(waitFor([&] {
    std::lock_guard<std::mutex> lock(static_mutex);
    return static_children.count(static_child) > 0;
  }, deadline)) << "a late subscriber got no /tf_static with " << static_child;

  EXPECT_TRUE(console.containing("TF_REPEATED_DATA").empty()) << console.containing("TF_REPEATED_DATA").front();
  console_bridge::restorePreviousOutputHandler();
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_FALSE(tf_stamps.empty());
  EXPECT_GE(passOf(tf_stamps.back()), passes) << "the transforms stayed behind /clock";
  for (size_t i = 0; i < tf_stamps.size(); ++i) {
    SCOPED_TRACE("transform " + std::to_string(i) + " received, pass " + std::to_string(passOf(tf_stamps[i])));
    if (i > 0) {
      ASSERT_GT(tf_stamps[i], tf_stamps[i - 1]) << "the stamps of " << child << " went back or repeated";
    }
    EXPECT_TRUE(bagStampShifted(tf_stamps[i])) << tf_stamps[i] << " is not a stamp of the bag, shifted with its pass";
  }
  // The bag's times are its stamps: /clock is shifted by the same amount on every pass.
  for (const ros::Time& c : clocks) EXPECT_TRUE(bagStampShifted(c)) << "/clock " << c;
  std::cout << "bag_player loop tf: " << tf_stamps.size() << " transforms over " << passOf(tf_stamps.back())
            << " passes of " << n << "; looked up at " << looked_up_at << " (pass " << passOf(looked_up_at) << ")\n";
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "bag_player_loop_tester");
}
