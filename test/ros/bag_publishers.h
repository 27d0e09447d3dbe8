// Publishers for every topic of a bag, for testers that feed a bag frame by frame themselves
// (replay_tester, flow_tester): each with the bag's own type (topic_tools::ShapeShifter), the mesh
// store latched as the bridge latches it.
#pragma once

#include <ros/ros.h>
#include <rosbag/view.h>
#include <topic_tools/shape_shifter.h>

#include <map>
#include <string>

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

}  // namespace test
}  // namespace viper
