// The ground-truth nodes as nodelets: the same classes as the nodes, so a whole replay can run
// zero-copy in one nodelet manager.
#include "viper/ros/ground_truth/boxes.h"
#include "viper/ros/ground_truth/instances.h"
#include "viper/ros/ground_truth/odometry.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

/// Nodelet shell around a node class T with T(nh, private_nh) and bool start().
template <typename T>
class ShellNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<T>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!node_->start()) NODELET_FATAL("nodelet '%s' not started (see the message above)", getName().c_str());
  }
  std::unique_ptr<T> node_;
};

class InstancesNodelet : public ShellNodelet<Instances> {};
class BoxesNodelet : public ShellNodelet<Boxes> {};
class OdometryNodelet : public ShellNodelet<Odometry> {};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::InstancesNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::BoxesNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::OdometryNodelet, nodelet::Nodelet)
