// bag_player as a nodelet: the same BagPlayer, sharing the bag's images zero-copy inside a manager.
#include "viper/ros/bridge/bag_player.h"
#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(BagPlayerNodelet, BagPlayer)
