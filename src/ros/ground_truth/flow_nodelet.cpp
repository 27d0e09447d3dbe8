// The flow node as a nodelet, so it runs zero-copy next to capture_bridge and instances.
#include "viper/ros/ground_truth/flow_node.h"
#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(FlowNodelet, Flow)
