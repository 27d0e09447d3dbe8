// The amodal node as a nodelet: the same class as the node.
#include "viper/ros/ground_truth/amodal_node.h"

#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(AmodalNodelet, Amodal)
