// instances: semantic and instance segmentation with track ids, from the raw capture topics and
// the resource label table. Topics and parameters: README.md and docs/ground_truth_nodes.md.
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ros/ground_truth/instances_step.h"
#include "viper/ros/ground_truth/step_log.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <image_transport/image_transport.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>

#include <map>
#include <memory>
#include <mutex>
#include <optional>

namespace viper {

/// The instances node's class, shared by the node and the nodelet.
class Instances {
 public:
  Instances(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Reads and validates the parameters, subscribes and advertises. Returns false after a
  /// ROS_FATAL saying how to fix an impossible configuration (e.g. no label table).
  bool start();
  uint64_t framesProcessed() const { return frames_; }

 private:
  using SyncPolicy = message_filters::sync_policies::ExactTime<DrawList, sensor_msgs::Image>;
  void onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::Image::ConstPtr& draw_ids);
  void onMeshStore(const MeshStore::ConstPtr& store);
  void onColor(const sensor_msgs::Image::ConstPtr& color);
  /// Publishes the overlay of `color` and `semantic` (same stamp); false with an error if the
  /// color image does not fit.
  void publishOverlay(const sensor_msgs::Image& color, const sensor_msgs::Image& semantic);
  std::string topicOf(StepInput input) const;

  ros::NodeHandle nh_, private_nh_;
  image_transport::ImageTransport it_;
  StepLog log_;
  std::unique_ptr<InstancesMessageStep> step_;
  std::mutex mutex_;

  message_filters::Subscriber<DrawList> draws_sub_;
  message_filters::Subscriber<sensor_msgs::Image> draw_ids_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Subscriber mesh_store_sub_;
  image_transport::Publisher semantic_pub_, semantic_color_pub_, instance_ids_pub_, boundaries_pub_, viper_pub_,
      overlay_pub_;
  image_transport::Subscriber color_sub_;
  float overlay_alpha_ = 0.5f;
  // The overlay pairs the camera image and the semantic image of one stamp, whichever comes first.
  std::map<ros::Time, sensor_msgs::Image::ConstPtr> pending_color_;
  std::map<ros::Time, sensor_msgs::Image::ConstPtr> pending_semantic_;  // the step's class id images
  ros::Publisher objects_pub_;

  uint64_t frames_ = 0;
  CpuMeter cpu_{"instances", nh_};  // per-frame CPU (cpu_meter.h)
};

/// Reads the class table named by ~class_table, or the package's config/viper_classes.csv.
/// Logs ROS_FATAL and returns nullopt if it cannot be read.
std::optional<ClassTable> loadClassTableParam(const ros::NodeHandle& private_nh);

}  // namespace viper
