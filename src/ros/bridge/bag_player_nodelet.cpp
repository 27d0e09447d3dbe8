// bag_player as a nodelet: the same BagPlayer, sharing the bag's images zero-copy inside a manager.
#include "viper/ros/bridge/bag_player.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class BagPlayerNodelet : public ShellNodelet<BagPlayer> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::BagPlayerNodelet, nodelet::Nodelet)
