// flow_baseline node (see docs/baselines.md).
#include "viper/ros/baselines/flow_baseline.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::FlowBaseline>(argc, argv, "flow_baseline"); }
