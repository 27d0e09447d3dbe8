// vo_baseline node (see docs/baselines.md).
#include "viper/ros/baselines/vo_baseline.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::VoBaseline>(argc, argv, "vo_baseline"); }
