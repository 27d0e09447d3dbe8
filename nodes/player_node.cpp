// player node: publishes a folder in VIPER's release layout as ground-truth topics (docs/viper_layout.md).
#include "viper/ros/dataset/player.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "player");
  viper::Player player(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!player.start(/*is_node=*/true)) {
    ros::shutdown();
    return 1;
  }
  ros::spin();
  player.stop();
  return 0;
}
