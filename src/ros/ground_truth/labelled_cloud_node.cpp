#include "viper/ros/ground_truth/labelled_cloud_node.h"

#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/node_params.h"

#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/PointField.h>

#include <stdexcept>

namespace viper {

std::string intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info, PinholeIntrinsics& out) {
  if (info.width == 0 || info.height == 0)
    return "camera info of " + std::to_string(info.width) + "x" + std::to_string(info.height) + " pixels";
  const auto& K = info.K;
  if (!(K[0] > 0.0) || !(K[4] > 0.0) || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0)
    return "camera info K is not a calibrated pinhole matrix (fx " + std::to_string(K[0]) + ", fy " +
           std::to_string(K[4]) + ", K[8] " + std::to_string(K[8]) + "): no camera for this frame";
  out.width = info.width, out.height = info.height;
  out.fx = K[0], out.skew = K[1], out.cx = K[2], out.fy = K[4], out.cy = K[5];
  return {};
}

void shapeLabelledCloudMsg(const CloudSize& size, sensor_msgs::PointCloud2& cloud) {
  auto field = [](const char* name, uint32_t offset, uint8_t type) {
    sensor_msgs::PointField f;
    f.name = name, f.offset = offset, f.datatype = type, f.count = 1;
    return f;
  };
  using F = sensor_msgs::PointField;
  cloud.fields = {field("x", offsetof(CloudPoint, x), F::FLOAT32), field("y", offsetof(CloudPoint, y), F::FLOAT32),
                  field("z", offsetof(CloudPoint, z), F::FLOAT32), field("rgb", offsetof(CloudPoint, rgb), F::FLOAT32),
                  field("label", offsetof(CloudPoint, label), F::UINT32),
                  field("instance", offsetof(CloudPoint, instance), F::UINT32)};
  cloud.width = size.width, cloud.height = size.height;
  cloud.is_bigendian = false;
  cloud.point_step = sizeof(CloudPoint);
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = false;
  cloud.data.resize(size.points() * sizeof(CloudPoint));
}

sensor_msgs::PointCloud2Ptr labelledCloudMsg(const sensor_msgs::Image& depth, const sensor_msgs::CameraInfo& info,
                                             const sensor_msgs::Image& color, const sensor_msgs::Image& semantic,
                                             const sensor_msgs::Image& instance_ids, int decimation,
                                             std::string& problem) {
  namespace enc = sensor_msgs::image_encodings;
  PinholeIntrinsics k;
  problem = intrinsicsFromCameraInfo(info, k);
  if (!problem.empty()) return nullptr;
  const uint32_t w = k.width, h = k.height;
  auto bad = [&](const char* what, const std::string& why) {
    problem = std::string(what) + ": " + why;
    return nullptr;
  };
  if (std::string p = checkImage(depth, enc::TYPE_32FC1, w, h); !p.empty()) return bad("depth", p);
  if (std::string p = checkImage(color, enc::RGB8, w, h); !p.empty()) return bad("color", p);
  if (std::string p = checkImage(semantic, enc::MONO8, w, h); !p.empty()) return bad("semantic", p);
  if (std::string p = checkImage(instance_ids, enc::TYPE_32SC1, w, h); !p.empty()) return bad("instance_ids", p);
  CloudImages images;
  images.width = w, images.height = h;
  images.depth_m = reinterpret_cast<const float*>(depth.data.data());
  images.rgb = color.data.data();
  images.class_ids = semantic.data.data();
  images.instance_ids = reinterpret_cast<const int32_t*>(instance_ids.data.data());
  auto cloud = boost::make_shared<sensor_msgs::PointCloud2>();
  cloud->header = depth.header;
  shapeLabelledCloudMsg(cloudSize(w, h, decimation), *cloud);
  labelledCloud(images, k, decimation, reinterpret_cast<CloudPoint*>(cloud->data.data()));
  return cloud;
}

LabelledCloud::LabelledCloud(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), it_(nh) {}

LabelledCloud::~LabelledCloud() {
  cloud_pub_.shutdown();
  if (inputs_) inputs_->stop();
}

bool LabelledCloud::start() {
  queue_size_ = queueSizeParam(private_nh_);
  private_nh_.param("decimation", decimation_, 1);
  if (decimation_ < 1) {
    ROS_ERROR("%s: ~decimation must be >= 1 (every k-th pixel in both directions; got %d); using 1",
              private_nh_.getNamespace().c_str(), decimation_);
    decimation_ = 1;
  }
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(queue_size_), depth_sub_, info_sub_,
                                                                      color_sub_, semantic_sub_, instance_ids_sub_);
  sync_->registerCallback(&LabelledCloud::onFrame, this);
  inputs_ = std::make_unique<LazyInputs>(
      [this] {
        info_sub_.subscribe(nh_, "camera_info", queue_size_);
        for (auto [sub, topic] : imageInputs()) sub->subscribe(it_, topic, queue_size_, image_transport::TransportHints("raw"));
      },
      [this] {
        info_sub_.unsubscribe();
        for (auto [sub, topic] : imageInputs()) sub->unsubscribe();
      });
  const ros::SubscriberStatusCallback changed = [this](const ros::SingleSubscriberPublisher&) {
    inputs_->update([this] { return cloud_pub_.getNumSubscribers(); });
  };
  inputs_->advertise([&] {
    cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("labelled_cloud", queue_size_, changed, changed);
  });
  return true;
}

void LabelledCloud::onFrame(const Image::ConstPtr& depth, const Info::ConstPtr& info, const Image::ConstPtr& color,
                            const Image::ConstPtr& semantic, const Image::ConstPtr& instance_ids) {
  const CpuMeter::Scope cpu(cpu_, true);
  std::string problem;
  sensor_msgs::PointCloud2Ptr cloud;
  try {
    cloud = labelledCloudMsg(*depth, *info, *color, *semantic, *instance_ids, decimation_, problem);
  } catch (const std::exception& e) {
    problem = e.what();
  }
  if (!cloud) {
    ROS_ERROR_THROTTLE(5, "%s: frame at stamp %.6f (%s, %s, %s, %s, %s) has no cloud: %s",
                       private_nh_.getNamespace().c_str(), depth->header.stamp.toSec(), depth_sub_.getTopic().c_str(),
                       info_sub_.getTopic().c_str(), color_sub_.getTopic().c_str(), semantic_sub_.getTopic().c_str(),
                       instance_ids_sub_.getTopic().c_str(), problem.c_str());
    return;
  }
  cloud_pub_.publish(cloud);
}

}  // namespace viper
