// labelled_cloud: an organised sensor_msgs/PointCloud2 of the frame's depth in the optical frame,
// each point with its colour, class id and instance id, computed only while `labelled_cloud` has
// subscribers. Topics, parameters and the point layout: docs/ground_truth_nodes.md ("labelled_cloud").
#pragma once

#include "viper/ground_truth/labelled_cloud.h"
#include "viper/ros/ground_truth/lazy_inputs.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

namespace viper {

/// The intrinsics of a camera info message (K; its width and height), for labelledCloud. Returns ""
/// or what is wrong (a size of zero, K not a pinhole matrix with positive focal lengths: an
/// uncalibrated camera).
std::string intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info, PinholeIntrinsics& out);

/// Shapes `cloud` as an organised cloud of `size` points laid out as CloudPoint: fields x, y, z, rgb
/// (FLOAT32, rgb packed as PCL does), label and instance (UINT32), 24 bytes a point, little-endian,
/// not dense (NaN points); its data sized, not filled.
void shapeLabelledCloudMsg(const CloudSize& size, sensor_msgs::PointCloud2& cloud);

/// The cloud of one frame's messages: depth (32FC1 metres), its camera info, colour (rgb8), classes
/// (mono8) and instance ids (32SC1), every `decimation`-th pixel; with the depth's header. Null
/// with `problem` (naming the input) when an input does not fit.
sensor_msgs::PointCloud2Ptr labelledCloudMsg(const sensor_msgs::Image& depth, const sensor_msgs::CameraInfo& info,
                                             const sensor_msgs::Image& color, const sensor_msgs::Image& semantic,
                                             const sensor_msgs::Image& instance_ids, int decimation,
                                             std::string& problem);

/// The labelled cloud node's class, shared by the node and the nodelet.
class LabelledCloud {
 public:
  LabelledCloud(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  ~LabelledCloud();
  LabelledCloud(const LabelledCloud&) = delete;
  LabelledCloud& operator=(const LabelledCloud&) = delete;
  /// Reads the parameters (~decimation below 1: an error, 1 used) and advertises; the inputs are
  /// subscribed while `labelled_cloud` has subscribers. Always true.
  bool start();

 private:
  using Image = sensor_msgs::Image;
  using Info = sensor_msgs::CameraInfo;
  using SyncPolicy = message_filters::sync_policies::ExactTime<Image, Info, Image, Image, Image>;
  /// The image inputs and their topics.
  std::array<std::pair<image_transport::SubscriberFilter*, const char*>, 4> imageInputs() {
    return {{{&depth_sub_, "depth"}, {&color_sub_, "color"}, {&semantic_sub_, "semantic"},
             {&instance_ids_sub_, "instance_ids"}}};
  }
  void onFrame(const Image::ConstPtr& depth, const Info::ConstPtr& info, const Image::ConstPtr& color,
               const Image::ConstPtr& semantic, const Image::ConstPtr& instance_ids);

  ros::NodeHandle nh_, private_nh_;
  image_transport::ImageTransport it_;
  int queue_size_ = 10;
  int decimation_ = 1;
  image_transport::SubscriberFilter depth_sub_, color_sub_, semantic_sub_, instance_ids_sub_;
  message_filters::Subscriber<Info> info_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Publisher cloud_pub_;
  std::unique_ptr<LazyInputs> inputs_;
  CpuMeter cpu_{"labelled_cloud", nh_};  // per-frame CPU (cpu_meter.h)
};

}  // namespace viper
