// amodal: every tracked object's amodal mask and visibility (viper/AmodalInstanceArray) and an rgb8
// overlay of them for rviz, from the draws, the instances node's instance_ids and objects and the
// mesh store; each output computed only while it has subscribers, no input taken while neither
// has. Topics and parameters: docs/amodal.md ("The amodal node").
#pragma once

#include "viper/ground_truth/amodal.h"
#include "viper/ros/ground_truth/lazy_inputs.h"
#include "viper/ros/ground_truth/step_log.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <viper/AmodalInstanceArray.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <memory>
#include <mutex>
#include <string>

namespace viper {

/// The amodal node's work on messages: the mesh store's meshes, and one frame's draw list,
/// instance ids (32SC1) and objects into the frame's amodal objects.
class AmodalMessageStep {
 public:
  /// Meshes of a mesh store message (those not held yet).
  void addMeshes(const MeshStore& store, StepProblems& problems);
  /// The frame's amodal objects into `amodal`, or false when the frame has none (its inputs do not
  /// fit: `problems` says why, naming the input). Objects that cannot be drawn are left out and
  /// named in `problems`.
  bool process(const DrawList& draws, const sensor_msgs::Image& instance_ids, const ObjectArray& objects,
               FrameAmodal& amodal, StepProblems& problems);

 private:
  MeshRegistry meshes_;
  CaptureFrame frame_;
  AmodalStep step_;
};

/// The amodal node's class, shared by the node and the nodelet.
class Amodal {
 public:
  Amodal(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Unsubscribes before any member goes (a nodelet is unloaded while callbacks may run).
  ~Amodal();
  Amodal(const Amodal&) = delete;
  Amodal& operator=(const Amodal&) = delete;
  /// Reads the parameters and advertises; the frame inputs are subscribed while `amodal/objects`
  /// or `amodal/overlay` has subscribers. Always true.
  bool start();

 private:
  using SyncPolicy = message_filters::sync_policies::ExactTime<DrawList, sensor_msgs::Image, ObjectArray>;
  void onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::ImageConstPtr& instance_ids,
               const ObjectArray::ConstPtr& objects);
  void onMeshStore(const MeshStore::ConstPtr& store);
  std::string topicOf(StepInput input) const;

  ros::NodeHandle nh_, private_nh_;
  image_transport::ImageTransport it_;
  StepLog log_;
  std::unique_ptr<AmodalMessageStep> step_;
  std::mutex mutex_;  // guards step_ and amodal_
  FrameAmodal amodal_;
  int queue_size_ = 10;

  message_filters::Subscriber<DrawList> draws_sub_;
  image_transport::SubscriberFilter instance_ids_sub_;
  message_filters::Subscriber<ObjectArray> objects_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Subscriber mesh_store_sub_;
  ros::Publisher objects_pub_;
  image_transport::Publisher overlay_pub_;
  std::unique_ptr<LazyInputs> inputs_;
  CpuMeter cpu_{"amodal", nh_};  // per-frame CPU (cpu_meter.h)
};

}  // namespace viper
