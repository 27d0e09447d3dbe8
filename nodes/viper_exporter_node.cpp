// viper_exporter node: writes live ground-truth topics into VIPER's release layout (docs/viper_layout.md).
#include "viper/ros/dataset/viper_exporter_node.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::ViperExporterNode>(argc, argv, "viper_exporter"); }
