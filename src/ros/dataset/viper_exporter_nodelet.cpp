// The viper_exporter node as a nodelet: the same ViperExporterNode, reading the ground truth
// zero-copy inside a manager.
#include "viper/ros/dataset/viper_exporter_node.h"
#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(ViperExporterNodelet, ViperExporterNode)
