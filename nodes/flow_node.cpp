// flow node (see docs/flow_node.md).
#include "viper/ros/ground_truth/flow_node.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::Flow>(argc, argv, "flow"); }
