// boxes: oriented 3D boxes of the tracked objects, in the map frame and in the camera optical
// frame, as typed arrays and rviz markers. Topics and parameters: docs/ground_truth_nodes.md.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ros/ground_truth/boxes_step.h"
#include "viper/ros/ground_truth/step_log.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <map>
#include <memory>
#include <mutex>
#include <optional>

namespace viper {

/// The boxes node's class, shared by the node and the nodelet.
class Boxes {
 public:
  Boxes(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Reads parameters, subscribes and advertises; false after ROS_FATAL on impossible settings.
  bool start();

 private:
  using SyncPolicy = message_filters::sync_policies::ExactTime<ObjectArray, DrawList>;
  void onFrame(const ObjectArray::ConstPtr& objects, const DrawList::ConstPtr& draws);
  void onMeshStore(const MeshStore::ConstPtr& store);
  std::string topicOf(StepInput input) const;

  ros::NodeHandle nh_, private_nh_;
  StepLog log_;
  std::unique_ptr<BoxesMessageStep> step_;
  std::mutex mutex_;

  message_filters::Subscriber<ObjectArray> objects_sub_;
  message_filters::Subscriber<DrawList> draws_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Subscriber mesh_store_sub_;
  ros::Publisher boxes_pub_, boxes_optical_pub_, markers_pub_;
  CpuMeter cpu_{"boxes", nh_};  // per-frame CPU (cpu_meter.h)
};

}  // namespace viper
