// rostest tester for the players' back-pressure (~pace_topic, pace_gate.h): a deliberately slow
// consumer of /capture/draws (max_in_flight messages queued, ~work_s of work a frame) that reports each frame
// it finished on /consumer/finished (std_msgs/Header). With the player paced by that topic at ~rate 0, every
// frame of the source arrives, in order, and never more than ~max_in_flight frames ahead of what was
// finished; without pacing (~paced false) the same consumer loses frames, which shows the test can
// tell the two apart.
//
// Private parameters: bag or capture (the source played; its frames are counted from it), paced
// (true), max_in_flight (2), work_s (0.05), timeout_s (60).
#include "tester_main.h"
#include "viper/capture/capture_stream.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Header.h>
#include <viper/DrawList.h>

#include <atomic>
#include <mutex>
#include <vector>

namespace {

size_t framesOfSource(const ros::NodeHandle& pnh) {
  std::string path;
  if (pnh.getParam("bag", path)) {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    return rosbag::View(bag, rosbag::TopicQuery("/capture/draws")).size();
  }
  if (!pnh.getParam("capture", path)) return 0;
  viper::CaptureReader reader(path);
  viper::CaptureFrame frame;
  size_t n = 0;
  while (reader.nextWithoutImages(frame) == viper::CaptureReader::Status::kFrame) ++n;
  return n;
}

TEST(BackPressure, EveryFrameArrivesWhenPacedAndSomeAreLostWhenNot) {
  ros::NodeHandle nh, pnh("~");
  const bool paced = pnh.param("paced", true);
  const int max_in_flight = pnh.param("max_in_flight", 2);
  const double work_s = pnh.param("work_s", 0.05);
  const size_t n = framesOfSource(pnh);
  ASSERT_GE(n, 10u) << "give ~bag or ~capture with at least 10 frames";

  ros::Publisher finished = nh.advertise<std_msgs::Header>("/consumer/finished", 100);
  std::mutex mutex;
  std::vector<ros::Time> stamps;  // of the frames received, in order
  std::atomic<size_t> ahead_max{0};
  // A queue of max_in_flight frames: the one being worked on is in flight too, and the next frame may
  // arrive (the player sees this one finished) before the queue has handed out the one waiting. An
  // unpaced player at rate 0 overruns it.
  const uint32_t queue = static_cast<uint32_t>(max_in_flight);
  ros::Subscriber sub = nh.subscribe<viper::DrawList>("/capture/draws", queue, [&](const viper::DrawList::ConstPtr& m) {
    ros::WallDuration(work_s).sleep();
    {
      std::lock_guard<std::mutex> lock(mutex);
      stamps.push_back(m->header.stamp);
    }
    std_msgs::HeaderPtr h(new std_msgs::Header);
    h->stamp = m->header.stamp;
    finished.publish(h);
  });
  // Counts what the player has sent beyond what was finished, from a second subscriber that keeps all.
  std::vector<ros::Time> sent;
  ros::Subscriber all = nh.subscribe<viper::DrawList>("/capture/draws", 1000, [&](const viper::DrawList::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    sent.push_back(m->header.stamp);
    const size_t done = stamps.size();
    if (sent.size() > done) ahead_max = std::max<size_t>(ahead_max, sent.size() - done);
  });

  ros::AsyncSpinner spinner(2);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout_s", 60.0));
  // Done when the player has sent every frame and nothing new came for 2 s.
  size_t last_count = 0;
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.05).sleep();
    std::lock_guard<std::mutex> lock(mutex);
    if (stamps.size() != last_count) last_count = stamps.size(), last_change = ros::WallTime::now();
    if (sent.size() >= n && (ros::WallTime::now() - last_change).toSec() > 2.0) break;
  }
  spinner.stop();
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(sent.size(), n) << "the player did not send every frame of the source";
  for (size_t i = 1; i < stamps.size(); ++i) EXPECT_LT(stamps[i - 1], stamps[i]) << "frame " << i << " out of order";
  if (paced) {
    EXPECT_EQ(stamps.size(), n) << "a paced player lost frames at the slow consumer";
    // The second subscriber sees a frame before the consumer has finished the one before it.
    EXPECT_LE(ahead_max.load(), static_cast<size_t>(max_in_flight) + 1);
  } else {
    EXPECT_LT(stamps.size(), n) << "without pacing the slow consumer kept up: the paced run proves nothing";
  }
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "back_pressure_tester");
}
