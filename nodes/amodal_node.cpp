// amodal node (see docs/amodal.md).
#include "viper/ros/ground_truth/amodal_node.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::Amodal>(argc, argv, "amodal"); }
