// flow_baseline node (see docs/baselines.md).
#include "viper/ros/baselines/flow_baseline.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "flow_baseline");
  viper::FlowBaseline node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.start()) return 1;
  ros::spin();
  return 0;
}
