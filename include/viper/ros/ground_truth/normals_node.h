// normals: the surface normal of every pixel (32FC3, the camera's optical frame) from the raw
// capture topics, computed only while `normals` has subscribers. Topics and parameters:
// docs/ground_truth_nodes.md ("normals").
#pragma once

#include "viper/ground_truth/normals.h"
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
#include <viper/DrawList.h>
#include <viper/MeshStore.h>

#include <memory>
#include <mutex>
#include <string>

namespace viper {

/// The normals node's work on messages: the mesh store's meshes, and one frame's draw list, draw
/// ids, primitive ids and depth (32FC1 metres) into a 32FC3 image with the draw ids' header.
class NormalsMessageStep {
 public:
  /// Meshes of a mesh store message (those not held yet).
  void addMeshes(const MeshStore& store, StepProblems& problems);
  /// The frame's normals, or null when the frame has none (its inputs do not fit: `problems` says
  /// why). Draws whose triangles cannot be found leave NaN pixels, named in `problems`.
  sensor_msgs::ImagePtr process(const DrawList& draws, const sensor_msgs::ImageConstPtr& draw_ids,
                                const sensor_msgs::ImageConstPtr& primitive_ids,
                                const sensor_msgs::ImageConstPtr& depth, StepProblems& problems);

 private:
  MeshRegistry meshes_;
  NormalsStep step_;
};

/// The normals node's class, shared by the node and the nodelet.
class Normals {
 public:
  Normals(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Unsubscribes before any member goes (a nodelet is unloaded while callbacks may run).
  ~Normals();
  Normals(const Normals&) = delete;
  Normals& operator=(const Normals&) = delete;
  /// Reads the parameters and advertises; the frame inputs are subscribed while `normals` has
  /// subscribers. Always true.
  bool start();

 private:
  using Image = sensor_msgs::Image;
  using SyncPolicy = message_filters::sync_policies::ExactTime<DrawList, Image, Image, Image>;
  void onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::ImageConstPtr& draw_ids,
               const sensor_msgs::ImageConstPtr& primitive_ids, const sensor_msgs::ImageConstPtr& depth);
  void onMeshStore(const MeshStore::ConstPtr& store);
  std::string topicOf(StepInput input) const;

  ros::NodeHandle nh_, private_nh_;
  image_transport::ImageTransport it_;
  StepLog log_;
  std::unique_ptr<NormalsMessageStep> step_;
  std::mutex mutex_;  // guards step_
  int queue_size_ = 10;

  message_filters::Subscriber<DrawList> draws_sub_;
  image_transport::SubscriberFilter draw_ids_sub_, primitive_ids_sub_, depth_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Subscriber mesh_store_sub_;
  image_transport::Publisher normals_pub_;
  std::unique_ptr<LazyInputs> inputs_;
  CpuMeter cpu_{"normals", nh_};  // per-frame CPU (cpu_meter.h)
};

}  // namespace viper
