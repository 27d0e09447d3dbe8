// evaluate node (see docs/evaluate.md): the report is written when the node shuts down.
#include "viper/ros/evaluation/evaluate.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "evaluate");
  viper::Evaluate node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.start()) return 1;
  ros::spin();
  return 0;
}
