// bag_player node: plays a raw bag paced by its times (see docs/capture_bridge.md#bag_player).
#include "viper/ros/bridge/bag_player.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::BagPlayer>(argc, argv, "bag_player"); }
