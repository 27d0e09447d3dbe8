// vo_baseline node (see docs/baselines.md).
#include "viper/ros/baselines/vo_baseline.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "vo_baseline");
  viper::VoBaseline node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.start()) return 1;
  ros::spin();
  return 0;
}
