// rostest tester for bag_player with ~loop: the bag's draw lists arrive pass after pass, each pass
// the bag's own messages but for their header stamps (and sequence numbers), which keep increasing across the start-over
// (the next pass begins one mean frame interval after the last stamp), shifted alike on every
// per-frame topic (the color images carry the draw lists' stamps); /clock never goes back.
//
// Private parameters: bag (path, required), passes (2: how many whole passes to wait for),
// timeout_s (90).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>

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

bool waitFor(const std::function<bool()>& done, const ros::WallTime& deadline) {
  while (!done()) {
    if (ros::WallTime::now() > deadline || !ros::ok()) return false;
    ros::WallDuration(0.01).sleep();
  }
  return true;
}

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
  ros::WallDuration(0.3).sleep();  // the images of the last frame counted

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

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "bag_player_loop_tester");
  return RUN_ALL_TESTS();
}
