// capture_bridge node: publishes a capture stream as raw topics (see docs/capture_bridge.md).
#include "viper/ros/bridge/capture_bridge.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "capture_bridge");
  viper::CaptureBridge bridge(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!bridge.start(/*is_node=*/true)) {
    ros::shutdown();
    return 1;
  }
  ros::spin();
  bridge.stop();
  return 0;
}
