// The player as a nodelet: the same Player, sharing images zero-copy inside a manager.
#include "viper/ros/dataset/player.h"
#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(PlayerNodelet, Player)
