#include "viper/ros/dataset/viper_exporter.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/dataset/viper_layout_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <algorithm>

namespace viper {
namespace {

// An 8-bit image message as the writer takes it: its pixels where they are when packed in
// `encoding`, else copied (imageFromMsg: any step, bgr8 for rgb8) into `copy`. "" or what is wrong.
std::string imageOf(const sensor_msgs::ImageConstPtr& msg, const std::string& encoding, dataset::ImageView8& view,
                    PixelOwner& owner) {
  if (checkImage(*msg, encoding).empty()) {
    view = dataset::ImageView8(msg->data.data(), msg->width, msg->height, static_cast<uint32_t>(bytesPerPixel(encoding)));
    owner = messageOwner(msg);
    return "";
  }
  auto copy = std::make_shared<dataset::Image8>();
  const std::string problem = imageFromMsg(*msg, encoding, *copy);
  if (!problem.empty()) return problem;
  view = dataset::ImageView8(*copy);
  owner = copy;
  return "";
}

}  // namespace

std::string ViperExporter::addColor(uint64_t frame, const sensor_msgs::Image& msg) {
  dataset::Image8 rgb;
  const std::string problem = imageFromMsg(msg, "rgb8", rgb);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addColor(frame, rgb, nullptr);
}

std::string ViperExporter::addColor(uint64_t frame, const sensor_msgs::ImageConstPtr& msg) {
  dataset::ImageView8 rgb;
  PixelOwner owner;
  const std::string problem = imageOf(msg, "rgb8", rgb, owner);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addColor(frame, rgb, owner);
}

std::string ViperExporter::addSemantic(uint64_t frame, const sensor_msgs::ImageConstPtr& msg) {
  dataset::ImageView8 ids;
  PixelOwner owner;
  const std::string problem = imageOf(msg, "mono8", ids, owner);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addSemantic(frame, ids, owner);
}

std::string ViperExporter::addInstanceIds(uint64_t frame, const sensor_msgs::ImageConstPtr& msg) {
  if (checkImage(*msg, sensor_msgs::image_encodings::TYPE_32SC1).empty())
    return writer_.addInstanceIds(frame, reinterpret_cast<const int32_t*>(msg->data.data()), msg->width, msg->height,
                                  messageOwner(msg));
  auto ids = std::make_shared<std::vector<int32_t>>();
  const std::string problem = int32FromMsg(*msg, *ids);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addInstanceIds(frame, ids->data(), msg->width, msg->height, ids);
}

std::string ViperExporter::addInstancesViper(uint64_t frame, const sensor_msgs::Image& msg) {
  dataset::Image8 inst;
  const std::string problem = imageFromMsg(msg, "rgb8", inst);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addInstancesViper(frame, inst, nullptr);
}

std::string ViperExporter::addInstancesViper(uint64_t frame, const sensor_msgs::ImageConstPtr& msg) {
  dataset::ImageView8 inst;
  PixelOwner owner;
  const std::string problem = imageOf(msg, "rgb8", inst, owner);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addInstancesViper(frame, inst, owner);
}

std::string ViperExporter::addFlow(uint64_t frame, const sensor_msgs::ImageConstPtr& msg, bool backward) {
  // Rows without padding are written from the message itself (it is shared and never changes): at
  // 1080p that saves copying 16.6 MB a flow image.
  if (msg->step == static_cast<size_t>(msg->width) * 8 && msg->encoding == sensor_msgs::image_encodings::TYPE_32FC2 &&
      msg->data.size() == static_cast<size_t>(msg->step) * msg->height)
    return writer_.addFlow(frame, reinterpret_cast<const float*>(msg->data.data()), msg->width, msg->height,
                           messageOwner(msg), backward);
  auto flow = std::make_shared<dataset::FlowImage>();
  const std::string problem = flowFromMsg(*msg, *flow);
  if (!problem.empty()) return writer_.skip(problem);
  return writer_.addFlow(frame, flow->uv.data(), msg->width, msg->height, flow, backward);
}

std::string ViperExporter::addBoxesOptical(uint64_t frame, const Box3DArray::ConstPtr& msg) {
  std::vector<ViperBox> boxes;
  boxes.reserve(msg->boxes.size());
  for (const Box3D& b : msg->boxes) boxes.push_back(ViperBox{fromBox3DMsg(b), b.class_id, b.id});
  return writer_.addBoxesOptical(frame, std::move(boxes));
}

std::string ViperExporter::addObjects(uint64_t frame, const ObjectArray::ConstPtr& msg) {
  // 2D boxes: the objects' (the tight box of their visible pixels).
  Boxes2d boxes_2d;
  for (const Object& o : msg->objects)
    if (o.track_id > 0 && o.box_2d.width > 0 && o.box_2d.height > 0)
      boxes_2d[o.track_id] = {{double(o.box_2d.x_offset), double(o.box_2d.y_offset),
                               double(o.box_2d.x_offset + o.box_2d.width - 1),
                               double(o.box_2d.y_offset + o.box_2d.height - 1)}};
  return writer_.addObjects(frame, std::move(boxes_2d));
}

std::string ViperExporter::addDraws(uint64_t frame, const DrawList& msg) {
  if (writer_.options().camera != CameraSource::kDraws) return "";
  CaptureFrame capture;
  fromDrawListMsg(msg, capture);
  return writer_.addCamera(frame, chooseFrameCamera(capture));
}

std::string ViperExporter::addOdometry(uint64_t frame, const nav_msgs::Odometry& msg) {
  if (writer_.options().camera != CameraSource::kOdometry) return "";
  return writer_.addOdometry(frame, fromPoseMsg(msg.pose.pose));
}

std::string ViperExporter::addCameraInfo(uint64_t frame, const sensor_msgs::CameraInfo& msg) {
  std::array<double, 9> K;
  std::copy(msg.K.begin(), msg.K.end(), K.begin());
  return writer_.addCameraInfo(frame, K, msg.width, msg.height);
}

}  // namespace viper
