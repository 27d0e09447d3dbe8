// The normals and labelled cloud nodes as nodelets: the same classes as the nodes.
#include "viper/ros/ground_truth/labelled_cloud_node.h"
#include "viper/ros/ground_truth/normals_node.h"

#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(NormalsNodelet, Normals)
VIPER_SHELL_NODELET(LabelledCloudNodelet, LabelledCloud)
