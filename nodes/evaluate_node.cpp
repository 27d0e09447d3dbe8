// evaluate node (see docs/evaluate.md): the report is written when the node shuts down.
#include "viper/ros/evaluation/evaluate.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::Evaluate>(argc, argv, "evaluate"); }
