// The ground-truth steps' inputs and results <-> messages (ground_truth_conversions.h): a frame's raw
// messages decoded into a GroundTruthInput that reads their pixels where they are, and the steps'
// results back as messages: instance images in recycled messages, boxes, odometry with tf and path,
// flows in recycled messages.
#include "viper/ros/conversions/ground_truth_conversions.h"

#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace viper {
namespace {

ClassTable classes() { return ClassTable::load("config/viper_classes.csv"); }

std_msgs::Header header(double t, const std::string& frame_id = "camera_optical") {
  std_msgs::Header h;
  h.stamp = ros::Time(t);
  h.frame_id = frame_id;
  h.seq = 7;
  return h;
}

// A 4x2 frame of two draws (the second with a view and a projection), as the bridge's messages.
struct RawMessages {
  CaptureFrame frame;
  DrawListPtr draws;
  sensor_msgs::ImagePtr draw_ids, depth, primitive_ids;
};
RawMessages rawMessages(double t) {
  RawMessages m;
  CaptureFrame& f = m.frame;
  f.number = 12, f.width = 4, f.height = 2, f.condition = "day";
  f.draws.resize(2);
  f.draws[0].index = 0, f.draws[0].mesh_key = 0x11;
  f.draws[1].index = 1, f.draws[1].mesh_key = 0x22, f.draws[1].matrix_flags = kHasWorld | kHasView | kHasProjection;
  f.draws[1].view(2, 3) = -10.0f;
  f.draws[1].visible_pixels = 4;
  f.draw_ids = {0, 1, 1, 2, 2, 2, 2, 0};
  f.primitive_ids = {0, 0, 1, 0, 1, 2, 3, 0};
  const std_msgs::Header h = header(t);
  m.draws = boost::make_shared<DrawList>(toDrawListMsg(f, h));
  m.draw_ids = boost::make_shared<sensor_msgs::Image>(drawIdImage(f, h));
  m.depth = boost::make_shared<sensor_msgs::Image>(depthImage(f, std::vector<float>(8, 5.0f), h));
  m.primitive_ids = boost::make_shared<sensor_msgs::Image>(primitiveIdImage(f, h));
  return m;
}

TEST(GroundTruthConversions, StampRoundTrip) {
  const ros::Time t(1234, 567890123);
  const FrameStamp s = toFrameStamp(t);
  EXPECT_EQ(s.sec, 1234u);
  EXPECT_EQ(s.nsec, 567890123u);
  EXPECT_EQ(toRosTime(s), t);
  EXPECT_EQ(s.seconds(), t.toSec()) << "velocities over stamps are the same doubles as over ros::Time";
  EXPECT_TRUE(toFrameStamp(ros::Time(3, 0)) < toFrameStamp(ros::Time(3, 1)));
  EXPECT_FALSE(toFrameStamp(ros::Time(3, 1)) <= toFrameStamp(ros::Time(2, 999999999)));
}

TEST(GroundTruthConversions, DecodedFrameReadsThePixelsInTheMessages) {
  const RawMessages m = rawMessages(2.5);
  GroundTruthInput in;
  ASSERT_EQ(decodeDrawMsgs(*m.draws, m.draw_ids, in), "");
  EXPECT_EQ(in.frame.number, 12u);
  EXPECT_EQ(in.frame.width, 4u);
  EXPECT_EQ(in.frame.height, 2u);
  EXPECT_EQ(in.frame.condition, "day");
  EXPECT_DOUBLE_EQ(in.frame.time_s, 2.5);
  ASSERT_EQ(in.frame.draws.size(), 2u);
  EXPECT_EQ(in.frame.draws[1].mesh_key, 0x22u);
  EXPECT_EQ(in.frame.draws[1].view, m.frame.draws[1].view);
  EXPECT_EQ(in.stamp, toFrameStamp(ros::Time(2.5)));
  EXPECT_EQ(static_cast<const void*>(in.draw_ids), static_cast<const void*>(m.draw_ids->data.data()));
  EXPECT_EQ(in.draw_ids[3], 2u);
  EXPECT_EQ(headerOf(in).seq, 7u) << "the images' header, seq and all";
  EXPECT_EQ(in.depth_m, nullptr);

  std::string depth_problem, primitives_problem;
  decodeFlowMsgs(m.depth, m.primitive_ids, in, depth_problem, primitives_problem);
  EXPECT_EQ(depth_problem, "");
  EXPECT_EQ(primitives_problem, "");
  EXPECT_EQ(static_cast<const void*>(in.depth_m), static_cast<const void*>(m.depth->data.data()));
  EXPECT_FLOAT_EQ(in.depth_m[5], 5.0f);
  EXPECT_EQ(in.primitive_ids[6], 3u);
  // The owner holds the messages: the pixels outlive the caller's pointers.
  const auto* owner = static_cast<const InputMessages*>(in.owner.get());
  EXPECT_EQ(owner->draw_ids, m.draw_ids);
  EXPECT_EQ(owner->depth, m.depth);
  EXPECT_EQ(owner->primitive_ids, m.primitive_ids);
}

TEST(GroundTruthConversions, BadImagesAreNamedAndLeftOut) {
  RawMessages m = rawMessages(1.0);
  GroundTruthInput in;
  auto mono = boost::make_shared<sensor_msgs::Image>(*m.draw_ids);
  mono->encoding = "mono8";
  const std::string problem = decodeDrawMsgs(*m.draws, mono, in);
  EXPECT_NE(problem.find("draw_ids: "), std::string::npos) << problem;
  EXPECT_EQ(in.draw_ids, nullptr);
  EXPECT_EQ(in.frame.draws.size(), 2u) << "the draws are decoded whatever the ids (odometry reads them)";

  auto later = boost::make_shared<sensor_msgs::Image>(*m.draw_ids);
  later->header.stamp = ros::Time(1.5);
  EXPECT_EQ(decodeDrawMsgs(*m.draws, later, in), "draw_ids and draws have different stamps");

  ASSERT_EQ(decodeDrawMsgs(*m.draws, m.draw_ids, in), "");
  auto small = boost::make_shared<sensor_msgs::Image>(depthImage(m.frame, std::vector<float>(8, 1.0f), header(1.0)));
  small->width = 2, small->height = 4;
  std::string depth_problem, primitives_problem;
  decodeFlowMsgs(small, m.primitive_ids, in, depth_problem, primitives_problem);
  EXPECT_NE(depth_problem, "");
  EXPECT_EQ(primitives_problem, "");
  EXPECT_EQ(in.depth_m, nullptr);
  EXPECT_NE(in.primitive_ids, nullptr);
}

TEST(GroundTruthConversions, InstanceImagesGoIntoMessagesOfTheirHeader) {
  InstanceImagePools pools;
  InstanceImagesWanted want;
  want.boundaries = false;
  want.semantic_color = false;
  InstanceImagesInto into;
  const InstanceImageMessages m = pools.take(header(3.0), 4, 2, want, into);
  ASSERT_TRUE(m.semantic && m.instance_ids && m.instances_viper);
  EXPECT_FALSE(m.boundaries);
  EXPECT_FALSE(m.semantic_color);
  EXPECT_EQ(m.semantic->encoding, "mono8");
  EXPECT_EQ(m.instance_ids->encoding, "32SC1");
  EXPECT_EQ(m.instances_viper->encoding, "rgb8");
  EXPECT_EQ(m.instance_ids->header.stamp, ros::Time(3.0));
  EXPECT_EQ(m.instance_ids->step, 16u);
  EXPECT_EQ(into.semantic, m.semantic->data.data());
  EXPECT_EQ(static_cast<void*>(into.instance_ids), static_cast<void*>(m.instance_ids->data.data()));
  EXPECT_EQ(into.instances_viper, m.instances_viper->data.data());
  EXPECT_EQ(into.boundaries, nullptr);
  EXPECT_EQ(into.semantic_color, nullptr);
  // Wanted or not, the class ids have a message (the overlay reads them).
  InstanceImagesWanted none{false, false, false, false, false};
  const InstanceImageMessages n = pools.take(header(3.1), 4, 2, none, into);
  EXPECT_TRUE(n.semantic);
  EXPECT_FALSE(n.instance_ids);
}

TEST(GroundTruthConversions, BoxesInMapAndInTheOpticalFrame) {
  FrameBoxes boxes;
  TrackBox b;
  b.track_id = 5, b.class_id = 24;
  b.in_map.center = {10, 2, 0.8};
  b.in_map.size = {4, 1.8, 1.5};
  b.velocity_map = {1, 0, 0};
  b.in_optical.center = {0, 0, 12};
  b.in_optical.size = b.in_map.size;
  b.velocity_optical = {0, 0, -1};
  boxes.boxes = {b};
  boxes.has_optical = true;
  const BoxesMessages m = toBoxesMsgs(boxes, header(4.0), "map", classes());
  ASSERT_TRUE(m.in_map && m.in_optical);
  EXPECT_EQ(m.in_map->header.frame_id, "map");
  EXPECT_EQ(m.in_optical->header.frame_id, "camera_optical");
  EXPECT_EQ(m.in_map->header.stamp, ros::Time(4.0));
  ASSERT_EQ(m.in_map->boxes.size(), 1u);
  EXPECT_EQ(m.in_map->boxes[0].id, 5);
  EXPECT_EQ(m.in_map->boxes[0].class_name, "car");
  EXPECT_LT((fromBox3DMsg(m.in_map->boxes[0]).center - b.in_map.center).norm(), 1e-12);
  EXPECT_LT((fromBox3DMsg(m.in_optical->boxes[0]).center - b.in_optical.center).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(m.in_map->boxes[0].velocity.linear.x, 1.0);
  EXPECT_DOUBLE_EQ(m.in_optical->boxes[0].velocity.linear.z, -1.0);
  boxes.has_optical = false;
  EXPECT_FALSE(toBoxesMsgs(boxes, header(4.0), "map", classes()).in_optical) << "no view matrix: no optical boxes";
}

TEST(GroundTruthConversions, OdometryPoseTwistTfAndPath) {
  OdometrySettings settings;
  settings.path_max_poses = 2;
  OdometryMessages messages(settings);
  EgoFrame ego;
  ego.pose.map_from_body.translation() = Eigen::Vector3d(1, 2, 3);
  ego.pose.map_from_body.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  OdometryMessages::Output first = messages.convert(ego, header(1.0, ""));
  ASSERT_TRUE(first.odom);
  EXPECT_EQ(first.odom->header.frame_id, "map");
  EXPECT_EQ(first.odom->child_frame_id, "camera");
  EXPECT_LT((fromPoseMsg(first.odom->pose.pose).matrix() - ego.pose.map_from_body.matrix()).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(first.odom->twist.twist.linear.x, 0.0) << "no twist without a previous pose";
  EXPECT_EQ(first.map_to_body.child_frame_id, "camera");
  EXPECT_EQ(first.body_to_optical.child_frame_id, "camera_optical") << "an empty frame id names camera_optical";
  EXPECT_TRUE(first.optical_changed);
  ASSERT_TRUE(first.path);
  EXPECT_EQ(first.path->poses.size(), 1u);

  ego.twist = BodyTwist();
  ego.twist->linear_mps = {2, 0, 0};
  ego.twist->angular_radps = {0, 0, 0.5};
  const OdometryMessages::Output second = messages.convert(ego, header(2.0, ""));
  EXPECT_DOUBLE_EQ(second.odom->twist.twist.linear.x, 2.0);
  EXPECT_DOUBLE_EQ(second.odom->twist.twist.angular.z, 0.5);
  EXPECT_FALSE(second.optical_changed);
  EXPECT_EQ(messages.convert(ego, header(3.0, "")).path->poses.size(), 2u) << "at most path_max_poses";
  EXPECT_TRUE(messages.convert(ego, header(4.0, "other_optical")).optical_changed);

  settings.make_path = false;
  EXPECT_FALSE(OdometryMessages(settings).convert(ego, header(1.0)).path);
  settings.body_frame = "map";
  EXPECT_THROW(OdometryMessages{settings}, std::invalid_argument);
}

TEST(GroundTruthConversions, FlowsGoIntoMessagesWithTheHeaderOfTheirFirstFrame) {
  const RawMessages a = rawMessages(1.0), b = rawMessages(2.0);
  GroundTruthInput in_a, in_b;
  ASSERT_EQ(decodeDrawMsgs(*a.draws, a.draw_ids, in_a), "");
  ASSERT_EQ(decodeDrawMsgs(*b.draws, b.draw_ids, in_b), "");
  FlowMessagePools pools;
  const FlowBuffers forward = pools.take(FlowKind::kForward, in_a);
  const FlowBuffers backward = pools.take(FlowKind::kBackward, in_b);
  const FlowMessages& f = pools.messages(FlowKind::kForward);
  ASSERT_TRUE(f.flow && f.visible);
  EXPECT_EQ(f.flow->header.stamp, ros::Time(1.0));
  EXPECT_EQ(pools.messages(FlowKind::kBackward).flow->header.stamp, ros::Time(2.0));
  EXPECT_EQ(f.flow->encoding, sensor_msgs::image_encodings::TYPE_32FC2);
  EXPECT_EQ(f.visible->encoding, sensor_msgs::image_encodings::MONO8);
  EXPECT_EQ(f.flow->width, 4u);
  EXPECT_EQ(static_cast<void*>(forward.uv), static_cast<void*>(f.flow->data.data()));
  EXPECT_EQ(forward.visible, f.visible->data.data());
  EXPECT_NE(backward.uv, forward.uv);
  EXPECT_FALSE(pools.messages(FlowKind::kWide).flow);
  pools.clear();
  EXPECT_FALSE(pools.messages(FlowKind::kForward).flow);
}

}  // namespace
}  // namespace viper
