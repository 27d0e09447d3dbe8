// rostest tester for capture_to_bag: subscribes to every topic of a capture_bridge node replaying a
// capture and compares what arrives with capture_to_bag's bag of the same capture, message by message
// and byte by byte (so topics, types, stamps, frame ids and content). bag_player.test uses it the
// other way round: bag_player plays the bag, and what arrives must be the bag. Per-frame topics must match
// exactly, in order; the latched mesh store may lose a message the bridge replaced before sending it,
// so every mesh store received must be the bag's one with the same stamp, and the last ones equal.
//
// Private parameters: bag (path, required), namespace (/capture), timeout_s (90).
#include "message_bytes.h"
#include "tester_main.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Log.h>
#include <topic_tools/shape_shifter.h>

#include <cstring>
#include <functional>
#include <map>
#include <mutex>
#include <vector>

namespace {

using Bytes = std::vector<uint8_t>;

using viper::test::heldBytes;

// The stamp of a message whose first field is a std_msgs/Header (seq, then stamp).
ros::Time stampOf(const Bytes& b) {
  ros::Time t;
  if (b.size() >= 12) {
    std::memcpy(&t.sec, b.data() + 4, 4);
    std::memcpy(&t.nsec, b.data() + 8, 4);
  }
  return t;
}

using viper::test::waitFor;

TEST(CaptureToBag, BagHoldsWhatTheBridgePublishes) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path, ns;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  pnh.param("namespace", ns, std::string("/capture"));
  const double timeout_s = pnh.param("timeout_s", 90.0);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);

  // The bag, by topic, with each connection's type and latching.
  std::map<std::string, std::vector<Bytes>> expected;
  std::map<std::string, std::string> types, latching;
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    types[c->topic] = c->datatype;
    if (c->header && c->header->count("latching")) latching[c->topic] = c->header->at("latching");
  }
  for (const rosbag::MessageInstance& m : view) {
    EXPECT_EQ(m.getTime(), stampOf(heldBytes(m))) << m.getTopic() << ": written at its header stamp";
    expected[m.getTopic()].push_back(heldBytes(m));
  }
  const std::vector<std::string> per_frame = {"color/image_raw", "color/camera_info", "depth/image_raw",
                                              "depth/camera_info", "draw_ids", "primitive_ids", "draws"};
  ASSERT_EQ(expected.size(), per_frame.size() + 1) << "seven per-frame topics and the mesh store";
  const size_t frames = expected[ns + "/draws"].size();
  ASSERT_GE(frames, 2u);
  for (const std::string& t : per_frame) EXPECT_EQ(expected[ns + "/" + t].size(), frames) << t;
  EXPECT_EQ(latching[ns + "/mesh_store"], "1") << "the bridge latches the mesh store";
  EXPECT_EQ(types[ns + "/draws"], "viper/DrawList");
  EXPECT_EQ(types[ns + "/color/image_raw"], "sensor_msgs/Image");

  // What the bridge publishes.
  std::mutex mutex;
  std::map<std::string, std::vector<Bytes>> got;
  std::map<std::string, std::string> got_types;
  std::vector<ros::Subscriber> subs;
  for (const auto& [topic, messages] : expected) {
    const std::string t = topic;
    subs.push_back(nh.subscribe<topic_tools::ShapeShifter>(t, 1000, [&, t](const topic_tools::ShapeShifter::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex);
      got[t].push_back(heldBytes(*m));
      got_types[t] = m->getDataType();
    }));
  }
  ros::AsyncSpinner spinner(2);
  spinner.start();
  auto count = [&](const std::string& t) {
    std::lock_guard<std::mutex> lock(mutex);
    return got[t].size();
  };
  ASSERT_TRUE(waitFor([&] {
    for (const std::string& t : per_frame)
      if (count(ns + "/" + t) < frames) return false;
    return true;
  }, deadline)) << "the bridge did not publish " << frames << " frames (draws: " << count(ns + "/draws") << ")";
  // Give a stray extra message the time to show.
  ros::WallDuration(0.5).sleep();

  std::lock_guard<std::mutex> lock(mutex);
  for (const std::string& name : per_frame) {
    const std::string t = ns + "/" + name;
    EXPECT_EQ(got_types[t], types[t]) << t;
    ASSERT_EQ(got[t].size(), expected[t].size()) << t;
    for (size_t i = 0; i < frames; ++i)
      EXPECT_TRUE(got[t][i] == expected[t][i]) << t << " message " << i << " (stamp " << stampOf(expected[t][i])
                                               << ") differs: " << got[t][i].size() << " vs " << expected[t][i].size()
                                               << " bytes, stamp " << stampOf(got[t][i]);
  }
  const std::string store = ns + "/mesh_store";
  const auto& stores = got[store];
  ASSERT_FALSE(stores.empty()) << "no mesh store received";
  EXPECT_EQ(got_types[store], types[store]);
  size_t k = 0;
  for (const Bytes& s : stores) {
    while (k < expected[store].size() && stampOf(expected[store][k]) != stampOf(s)) ++k;
    ASSERT_LT(k, expected[store].size()) << "mesh store stamped " << stampOf(s) << " is not in the bag (or out of order)";
    EXPECT_TRUE(s == expected[store][k]) << "mesh store stamped " << stampOf(s) << " differs";
  }
  EXPECT_TRUE(stores.back() == expected[store].back()) << "the last mesh store";
  std::cout << "capture_to_bag_tester: " << frames << " frames equal on 7 topics; " << stores.size() << " of "
            << expected[store].size() << " mesh stores received, all equal\n";
}

// bag_player on a bag with a damaged chunk (~bag; ~intact_bag: the same bag undamaged): an error on
// /rosout names the bag; the draw lists that arrive are the intact bag's first ones, byte for byte,
// fewer than all; the player is still running afterwards.
TEST(BagPlayer, NamesTheDamageAndKeepsWhatCameBefore) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path, intact_path;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  ASSERT_TRUE(pnh.getParam("intact_bag", intact_path)) << "tester needs ~intact_bag";
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout_s", 60.0));
  std::vector<Bytes> intact;
  {
    rosbag::Bag bag(intact_path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/capture/draws")))
      intact.push_back(heldBytes(m));
  }
  ASSERT_GE(intact.size(), 2u);
  std::mutex mutex;
  std::vector<Bytes> got;
  std::string error;
  auto draws = nh.subscribe<topic_tools::ShapeShifter>("/capture/draws", 1000, [&](const topic_tools::ShapeShifter::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    got.push_back(heldBytes(*m));
  });
  auto rosout = nh.subscribe<rosgraph_msgs::Log>("/rosout", 100, [&](const rosgraph_msgs::Log::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    if (m->level == rosgraph_msgs::Log::ERROR && m->msg.find(bag_path) != std::string::npos) error = m->msg;
  });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(waitFor([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return !error.empty();
  }, deadline)) << "no error on /rosout naming " << bag_path;
  ros::WallDuration(0.5).sleep();
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_NE(error.find("damaged after"), std::string::npos) << error;
  EXPECT_GT(got.size(), 0u) << "nothing before the damage was published";
  EXPECT_LT(got.size(), intact.size()) << "the damage went unnoticed";
  for (size_t i = 0; i < got.size() && i < intact.size(); ++i) EXPECT_TRUE(got[i] == intact[i]) << "draw list " << i;
  EXPECT_TRUE(ros::service::exists("/bag_player/get_loggers", false)) << "the player did not keep running";
  std::cout << "bag_player: " << got.size() << " of " << intact.size() << " draw lists before the damage; " << error
            << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "capture_to_bag_tester");
}
