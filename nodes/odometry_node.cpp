// odometry node (see docs/ground_truth_nodes.md).
#include "viper/ros/ground_truth/odometry.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "odometry");
  viper::Odometry node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.start()) return 1;
  ros::spin();
  return 0;
}
