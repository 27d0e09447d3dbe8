// normals node (see docs/ground_truth_nodes.md).
#include "viper/ros/ground_truth/normals_node.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::Normals>(argc, argv, "normals"); }
