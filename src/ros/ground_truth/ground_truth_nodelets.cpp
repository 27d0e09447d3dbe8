// The ground-truth nodes as nodelets: the same classes as the nodes, so a whole replay can run
// zero-copy in one nodelet manager.
#include "viper/ros/ground_truth/boxes_node.h"
#include "viper/ros/ground_truth/instances_node.h"
#include "viper/ros/ground_truth/odometry_node.h"

#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(InstancesNodelet, Instances)
VIPER_SHELL_NODELET(BoxesNodelet, Boxes)
VIPER_SHELL_NODELET(OdometryNodelet, Odometry)
