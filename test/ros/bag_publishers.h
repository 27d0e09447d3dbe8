// Publishers for every topic of a bag, for testers that feed a bag frame by frame themselves
// (replay_tester, flow_tester): each with the bag's own type (topic_tools::ShapeShifter), the mesh
// store latched as the bridge latches it; and the bag's messages grouped by frame.
#pragma once

#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <topic_tools/shape_shifter.h>
#include <viper/DrawList.h>

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace viper {
namespace test {

inline std::map<std::string, ros::Publisher> advertiseBagTopics(ros::NodeHandle& nh, rosbag::View& view) {
  std::map<std::string, ros::Publisher> pubs;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    topic_tools::ShapeShifter shape;
    shape.morph(c->md5sum, c->datatype, c->msg_def, "");
    pubs[c->topic] = shape.advertise(nh, c->topic, 100, c->topic == "/capture/mesh_store");
  }
  return pubs;
}

/// A frame's messages: topic and message as the bag holds it.
using BagFrameMessages = std::vector<std::pair<std::string, topic_tools::ShapeShifter::ConstPtr>>;

/// The messages of `view` grouped by their header stamp (draw lists, images and camera infos; other
/// messages left out), each frame's in the bag's order, or with its camera infos first where
/// `camera_info_first`. The mesh store is published at once on its publisher in `pubs`, not grouped.
/// `each(message, stamp)`, where given, is shown every grouped message, for what a tester keeps.
inline std::map<ros::Time, BagFrameMessages> messagesByStamp(
    rosbag::View& view, std::map<std::string, ros::Publisher>& pubs, bool camera_info_first = false,
    const std::function<void(const rosbag::MessageInstance&, const ros::Time&)>& each = nullptr) {
  std::map<ros::Time, BagFrameMessages> by_stamp;
  for (const rosbag::MessageInstance& m : view) {
    const std::string& topic = m.getTopic();
    auto shape = m.instantiate<topic_tools::ShapeShifter>();
    if (topic == "/capture/mesh_store") {
      pubs[topic].publish(shape);
      continue;
    }
    ros::Time stamp;
    if (auto draws = m.instantiate<viper::DrawList>()) stamp = draws->header.stamp;
    else if (auto image = m.instantiate<sensor_msgs::Image>()) stamp = image->header.stamp;
    else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) stamp = info->header.stamp;
    else continue;
    if (each) each(m, stamp);
    BagFrameMessages& frame = by_stamp[stamp];
    if (camera_info_first && topic.find("camera_info") != std::string::npos) frame.insert(frame.begin(), {topic, shape});
    else frame.emplace_back(topic, shape);
  }
  return by_stamp;
}

/// A tester's bag: private parameter ~bag (required: throws without it) opened, a publisher for
/// each of its topics (advertiseBagTopics), and the deadline ~timeout_s (default 120 s) from now.
struct TesterBag {
  explicit TesterBag(ros::NodeHandle& nh) {
    ros::NodeHandle pnh("~");
    std::string path;
    if (!pnh.getParam("bag", path)) throw std::runtime_error("tester needs ~bag");
    bag.open(path, rosbag::bagmode::Read);
    view = std::make_unique<rosbag::View>(bag);
    pubs = advertiseBagTopics(nh, *view);
    deadline = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout_s", 120.0));
  }
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  std::map<std::string, ros::Publisher> pubs;
  ros::WallTime deadline;
};

/// Whether the master knows a publisher of every topic of `names`.
inline bool allAdvertised(const std::vector<std::string>& names) {
  ros::master::V_TopicInfo topics;
  ros::master::getTopics(topics);
  size_t found = 0;
  for (const std::string& name : names)
    for (const auto& t : topics) found += t.name == name;
  return found == names.size();
}

}  // namespace test
}  // namespace viper
