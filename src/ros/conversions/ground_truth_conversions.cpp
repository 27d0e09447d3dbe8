#include "viper/ros/conversions/ground_truth_conversions.h"

#include "viper/ground_truth/ego_motion.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>

#include <stdexcept>

namespace viper {

const std_msgs::Header& headerOf(const GroundTruthInput& input) {
  return static_cast<const InputMessages*>(input.owner.get())->header;
}

std::string decodeDrawMsgs(const DrawList& draws, const sensor_msgs::ImageConstPtr& draw_ids, GroundTruthInput& in) {
  in.draw_ids = nullptr, in.depth_m = nullptr, in.primitive_ids = nullptr;
  in.stamp = toFrameStamp(draws.header.stamp);
  auto owner = std::make_shared<InputMessages>();
  owner->header = draw_ids->header;
  in.owner = owner;
  // The draws whatever the ids: the odometry step reads only them. Then the ids as
  // frameFromDrawMsgs checks them.
  in.frame.time_s = draws.header.stamp.toSec();
  fromDrawListMsg(draws, in.frame);
  const std::string problem = checkImage(*draw_ids, sensor_msgs::image_encodings::TYPE_32SC1);
  if (!problem.empty()) return "draw_ids: " + problem;
  if (draw_ids->header.stamp != draws.header.stamp) return "draw_ids and draws have different stamps";
  in.frame.width = draw_ids->width;
  in.frame.height = draw_ids->height;
  owner->draw_ids = draw_ids;
  // Message buffers come from new[], aligned for any scalar type.
  in.draw_ids = reinterpret_cast<const uint32_t*>(draw_ids->data.data());
  return {};
}

void decodeFlowMsgs(const sensor_msgs::ImageConstPtr& depth, const sensor_msgs::ImageConstPtr& primitive_ids,
                    GroundTruthInput& in, std::string& depth_problem, std::string& primitives_problem) {
  // The owner is decodeDrawMsgs' own, not yet shared with anyone who reads it.
  auto* owner = const_cast<InputMessages*>(static_cast<const InputMessages*>(in.owner.get()));
  const uint32_t w = in.frame.width, h = in.frame.height;
  depth_problem = checkImage(*depth, sensor_msgs::image_encodings::TYPE_32FC1, w, h);
  if (depth_problem.empty()) {
    owner->depth = depth;
    in.depth_m = reinterpret_cast<const float*>(depth->data.data());
  }
  primitives_problem = checkImage(*primitive_ids, sensor_msgs::image_encodings::TYPE_32SC1, w, h);
  if (primitives_problem.empty()) {
    owner->primitive_ids = primitive_ids;
    in.primitive_ids = reinterpret_cast<const uint32_t*>(primitive_ids->data.data());
  }
}

InstanceImageMessages InstanceImagePools::take(const std_msgs::Header& header, uint32_t w, uint32_t h,
                                               const InstanceImagesWanted& want, InstanceImagesInto& into) {
  // The pipeline renders the instance ids in its own storage when nobody wants them (boundaries
  // need them). The class ids always go into a message: the overlay reads them when the color
  // image comes.
  InstanceImageMessages m;
  m.semantic = mono_pool_.take(header, w, h, "mono8", 1);
  if (want.instance_ids) m.instance_ids = ids_pool_.take(header, w, h, "32SC1", 4);
  if (want.boundaries) m.boundaries = mono_pool_.take(header, w, h, "mono8", 1);
  if (want.semantic_color) m.semantic_color = rgb_pool_.take(header, w, h, "rgb8", 3);
  if (want.instances_viper) m.instances_viper = rgb_pool_.take(header, w, h, "rgb8", 3);
  into.semantic = m.semantic->data.data();
  into.instance_ids = m.instance_ids ? reinterpret_cast<int32_t*>(m.instance_ids->data.data()) : nullptr;
  into.boundaries = m.boundaries ? m.boundaries->data.data() : nullptr;
  into.semantic_color = m.semantic_color ? m.semantic_color->data.data() : nullptr;
  into.instances_viper = m.instances_viper ? m.instances_viper->data.data() : nullptr;
  return m;
}

sensor_msgs::ImagePtr InstanceImagePools::takeRgb(const std_msgs::Header& header, uint32_t width, uint32_t height) {
  return rgb_pool_.take(header, width, height, "rgb8", 3);
}

BoxesMessages toBoxesMsgs(const FrameBoxes& boxes, const std_msgs::Header& draws_header, const std::string& map_frame,
                          const ClassTable& classes) {
  BoxesMessages out;
  out.in_map = boost::make_shared<Box3DArray>();
  out.in_map->header = draws_header;
  out.in_map->header.frame_id = map_frame;
  out.in_map->boxes.reserve(boxes.boxes.size());
  for (const TrackBox& b : boxes.boxes)
    out.in_map->boxes.push_back(toBox3DMsg(b.in_map, b.track_id, b.class_id, classes, b.velocity_map));
  if (boxes.has_optical) {
    out.in_optical = boost::make_shared<Box3DArray>();
    out.in_optical->header = draws_header;
    out.in_optical->boxes.reserve(boxes.boxes.size());
    for (const TrackBox& b : boxes.boxes)
      out.in_optical->boxes.push_back(toBox3DMsg(b.in_optical, b.track_id, b.class_id, classes, b.velocity_optical));
  }
  return out;
}

OdometryMessages::OdometryMessages(const OdometrySettings& settings) : settings_(settings) {
  if (settings_.map_frame.empty() || settings_.body_frame.empty() || settings_.map_frame == settings_.body_frame)
    throw std::invalid_argument("map_frame ('" + settings_.map_frame + "') and body_frame ('" + settings_.body_frame +
                                "') must be non-empty and differ");
  if (settings_.path_max_poses < 1)
    throw std::invalid_argument("path_max_poses must be >= 1 (got " + std::to_string(settings_.path_max_poses) + ")");
  path_.header.frame_id = settings_.map_frame;
}

OdometryMessages::Output OdometryMessages::convert(const EgoFrame& ego, const std_msgs::Header& draws_header) {
  Output out;
  const ros::Time stamp = draws_header.stamp;
  const std::string optical_frame = draws_header.frame_id.empty() ? "camera_optical" : draws_header.frame_id;
  out.map_to_body = toTransformMsg(ego.pose.map_from_body, stamp, settings_.map_frame, settings_.body_frame);
  out.body_to_optical = toTransformMsg(bodyFromOptical(), stamp, settings_.body_frame, optical_frame);
  out.optical_changed = optical_frame != optical_frame_;
  optical_frame_ = optical_frame;

  out.odom = boost::make_shared<nav_msgs::Odometry>();
  nav_msgs::Odometry& odom = *out.odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = settings_.map_frame;
  odom.child_frame_id = settings_.body_frame;
  odom.pose.pose = toPoseMsg(ego.pose.map_from_body);
  if (ego.twist) {
    const BodyTwist& twist = *ego.twist;
    odom.twist.twist.linear.x = twist.linear_mps.x(), odom.twist.twist.linear.y = twist.linear_mps.y();
    odom.twist.twist.linear.z = twist.linear_mps.z();
    odom.twist.twist.angular.x = twist.angular_radps.x(), odom.twist.twist.angular.y = twist.angular_radps.y();
    odom.twist.twist.angular.z = twist.angular_radps.z();
  }
  if (settings_.make_path) {
    geometry_msgs::PoseStamped ps;
    ps.header = odom.header;
    ps.pose = odom.pose.pose;
    path_.header.stamp = stamp;
    path_.poses.push_back(ps);
    if (static_cast<int>(path_.poses.size()) > settings_.path_max_poses) path_.poses.erase(path_.poses.begin());
    out.path = boost::make_shared<const nav_msgs::Path>(path_);
  }
  return out;
}

FlowBuffers FlowMessagePools::take(FlowKind kind, const GroundTruthInput& from) {
  // The flow writes every pixel: a recycled message needs no clearing.
  const std_msgs::Header& header = headerOf(from);
  const uint32_t w = from.frame.width, h = from.frame.height;
  FlowMessages& m = taken_[static_cast<int>(kind)];
  m.flow = flow_pool_.take(header, w, h, sensor_msgs::image_encodings::TYPE_32FC2, 8);
  m.visible = visible_pool_.take(header, w, h, sensor_msgs::image_encodings::MONO8, 1);
  return FlowBuffers{reinterpret_cast<float*>(m.flow->data.data()), m.visible->data.data()};
}

void FlowMessagePools::clear() {
  for (FlowMessages& m : taken_) m = FlowMessages();
}

}  // namespace viper
