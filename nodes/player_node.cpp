// player node: publishes a folder in VIPER's release layout as ground-truth topics (docs/viper_layout.md).
#include "viper/ros/dataset/player.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::Player>(argc, argv, "player"); }
