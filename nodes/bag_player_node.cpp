// bag_player node: plays a raw bag paced by its times (see docs/capture_bridge.md#bag_player).
#include "viper/ros/bridge/bag_player.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "bag_player");
  viper::BagPlayer player(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!player.start(/*is_node=*/true)) {
    ros::shutdown();
    return 1;
  }
  ros::spin();
  player.stop();
  return 0;
}
