// The player as a nodelet: the same Player, sharing images zero-copy inside a manager.
#include "viper/ros/dataset/player.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class PlayerNodelet : public ShellNodelet<Player> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::PlayerNodelet, nodelet::Nodelet)
