// boxes node (see docs/ground_truth_nodes.md).
#include "viper/ros/ground_truth/boxes.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "boxes");
  viper::Boxes node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.start()) return 1;
  ros::spin();
  return 0;
}
