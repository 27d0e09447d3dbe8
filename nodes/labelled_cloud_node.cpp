// labelled_cloud node (see docs/ground_truth_nodes.md).
#include "viper/ros/ground_truth/labelled_cloud_node.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::LabelledCloud>(argc, argv, "labelled_cloud"); }
