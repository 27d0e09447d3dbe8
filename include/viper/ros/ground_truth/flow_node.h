// flow: dense forward/backward optical flow, occlusion masks and wide-baseline correspondences from
// the raw capture topics and the instances node's objects. Topics, parameters, stamps and the
// service: docs/flow_node.md.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/flow.h"
#include "viper/ros/ground_truth/flow_step.h"
#include "viper/ros/ground_truth/step_log.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <Eigen/Geometry>
#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <viper/Correspondences.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// The flow node's class, shared by the node and the nodelet.
class Flow {
 public:
  Flow(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Shuts the inputs and the service down before any member goes (roscpp waits there for their
  /// callbacks in flight): the members are destroyed in reverse order, step_, the log and the
  /// publishers before the subscriptions that use them, and a nodelet is unloaded while the
  /// manager's threads may still be in a callback (ThreadSanitizer saw ~FlowNodelet destroy
  /// step_ with no order against the last FlowStep::process; docs/sanitizers.md).
  ~Flow() {
    draws_sub_.unsubscribe();
    depth_sub_.unsubscribe();
    draw_ids_sub_.unsubscribe();
    primitive_ids_sub_.unsubscribe();
    objects_sub_.unsubscribe();
    mesh_store_sub_.shutdown();
    correspondences_srv_.shutdown();
    // Released under the lock its callbacks take: the order ThreadSanitizer can see (roscpp's own
    // wait above is in code it does not see).
    std::lock_guard<std::mutex> lock(mutex_);
    step_.reset();
  }
  Flow(const Flow&) = delete;
  Flow& operator=(const Flow&) = delete;
  /// Reads and validates the parameters, subscribes, advertises and offers the service. Returns
  /// false after a ROS_FATAL saying how to fix an impossible configuration.
  bool start();
  uint64_t framesProcessed() const { return frames_; }

 private:
  using ImageConstPtr = sensor_msgs::Image::ConstPtr;
  using SyncPolicy = message_filters::sync_policies::ExactTime<DrawList, sensor_msgs::Image, sensor_msgs::Image,
                                                               sensor_msgs::Image, ObjectArray>;

  void onFrame(const DrawList::ConstPtr& draws, const ImageConstPtr& depth, const ImageConstPtr& draw_ids,
               const ImageConstPtr& primitive_ids, const ObjectArray::ConstPtr& objects);
  void onDrop(const DrawList::ConstPtr& draws, const ImageConstPtr& depth, const ImageConstPtr& draw_ids,
              const ImageConstPtr& primitive_ids, const ObjectArray::ConstPtr& objects);
  void onMeshStore(const MeshStore::ConstPtr& store);
  bool onCorrespondences(Correspondences::Request& req, Correspondences::Response& res);
  std::string topicOf(StepInput input) const;

  ros::NodeHandle nh_, private_nh_;
  image_transport::ImageTransport it_;

  message_filters::Subscriber<DrawList> draws_sub_;
  image_transport::SubscriberFilter depth_sub_, draw_ids_sub_, primitive_ids_sub_;
  message_filters::Subscriber<ObjectArray> objects_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Subscriber mesh_store_sub_;
  image_transport::Publisher forward_pub_, forward_visible_pub_, backward_pub_, backward_visible_pub_, wide_pub_,
      wide_visible_pub_;
  image_transport::Publisher scene_flow_pub_;  // flow/scene_flow: computed only while subscribed
  ros::ServiceServer correspondences_srv_;
  StepLog log_;

  std::mutex mutex_;  // guards the step
  std::unique_ptr<FlowMessageStep> step_;
  uint64_t frames_ = 0;
  CpuMeter cpu_{"flow", nh_};  // per-frame CPU (cpu_meter.h)
};

}  // namespace viper
