// flow node (see docs/flow_node.md).
#include "viper/ros/ground_truth/flow.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "flow");
  viper::Flow node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.start()) return 1;
  ros::spin();
  return 0;
}
