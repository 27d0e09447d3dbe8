// The ground-truth steps' inputs and results (include/viper/ground_truth/*_step.h) <-> messages: a
// frame's raw messages decoded into a GroundTruthInput (its pixels read where they are), and the
// steps' results as the nodes publish them (instance images into recycled messages, objects, boxes,
// odometry and tf, flow into recycled messages). The nodes and `generate` convert with these, so
// both publish the same messages. Part of the converter between messages and core types
// (include/viper/ros/conversions/; docs/design.md).
#pragma once

#include "viper/ground_truth/boxes_step.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/flow_step.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/odometry_step.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/conversions/image_msg_pool.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/time.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>

#include <memory>
#include <string>

namespace viper {

/// ros::Time <-> the steps' FrameStamp (the same seconds and nanoseconds).
inline FrameStamp toFrameStamp(const ros::Time& t) { return FrameStamp{t.sec, t.nsec}; }
inline ros::Time toRosTime(const FrameStamp& s) { return ros::Time(s.sec, s.nsec); }

/// Whoever holds a shared message: a std::shared_ptr keeping it (and its pixels) alive, for core
/// types that keep pixels where they are (GroundTruthInput::owner, PixelOwner).
template <typename M>
std::shared_ptr<const void> messageOwner(const boost::shared_ptr<M>& msg) {
  return std::shared_ptr<const void>(msg.get(), [msg](const void*) {});
}

/// What a GroundTruthInput decoded from messages holds on to (its `owner`): the messages its pixels
/// are in, and the header of its images (the draw id image's: the header of every image made of it).
struct InputMessages {
  std_msgs::Header header;
  sensor_msgs::ImageConstPtr draw_ids, depth, primitive_ids;
};
/// The header of an input whose owner is an InputMessages (decodeDrawMsgs made it).
const std_msgs::Header& headerOf(const GroundTruthInput& input);

/// A frame's draw list and draw id image into `in`: its frame (size, number, time, draws), stamp
/// and draw ids (read in the message), and an owner (InputMessages) holding the image. Returns ""
/// or what is wrong with the ids, as frameFromDrawMsgs words it (encoding, size, stamps that
/// differ); `in.draw_ids` is then null (and the size not set), the draws decoded all the same.
std::string decodeDrawMsgs(const DrawList& draws, const sensor_msgs::ImageConstPtr& draw_ids, GroundTruthInput& in);
/// A frame's depth (32FC1 metres) and primitive id (32SC1) images into `in` (decoded by
/// decodeDrawMsgs: their size must be its frame's), read in the messages, which its owner then
/// holds. `depth_problem` and `primitives_problem` get "" or what is wrong with each (checkImage);
/// the pointer of a bad one stays null.
void decodeFlowMsgs(const sensor_msgs::ImageConstPtr& depth, const sensor_msgs::ImageConstPtr& primitive_ids,
                    GroundTruthInput& in, std::string& depth_problem, std::string& primitives_problem);

/// Which instance images to make (the class ids always are: the overlay reads them).
struct InstanceImagesWanted {
  bool semantic = true, semantic_color = true, instance_ids = true, boundaries = true, instances_viper = true;
};
/// A frame's instance images as messages, each with the draw id image's header; null where not
/// wanted (semantic is made either way).
struct InstanceImageMessages {
  sensor_msgs::ImagePtr semantic, semantic_color, instance_ids, boundaries, instances_viper;
};
/// The instance images' messages, recycled (ImageMsgPool).
class InstanceImagePools {
 public:
  /// Messages for the wanted images of a `width` x `height` frame with `header`, and `into` (its
  /// semantic, semantic_color, instance_ids, boundaries, instances_viper) pointed at their pixels,
  /// every one of which the instances step writes.
  InstanceImageMessages take(const std_msgs::Header& header, uint32_t width, uint32_t height,
                             const InstanceImagesWanted& want, InstanceImagesInto& into);
  /// An rgb8 message of the pool (the overlay's).
  sensor_msgs::ImagePtr takeRgb(const std_msgs::Header& header, uint32_t width, uint32_t height);

 private:
  ImageMsgPool ids_pool_, mono_pool_, rgb_pool_{24};
};

/// A frame's boxes as the boxes node publishes them: in `map_frame` (always) and in the optical
/// frame (null when the frame had no usable view matrix), with the draw list's header.
struct BoxesMessages {
  Box3DArrayPtr in_map, in_optical;
};
BoxesMessages toBoxesMsgs(const FrameBoxes& boxes, const std_msgs::Header& draws_header, const std::string& map_frame,
                          const ClassTable& classes);

/// Frames and path of the odometry messages (the odometry node's parameters, with the same defaults).
struct OdometrySettings {
  std::string map_frame = "map", body_frame = "camera";
  int path_max_poses = 10000;
  bool make_path = true;  ///< the path message (a copy of every pose so far, each frame)
};

/// The odometry step's results as the odometry node publishes them. Keeps the path and the name of
/// the optical frame from frame to frame.
class OdometryMessages {
 public:
  /// Throws std::invalid_argument if the frames are empty or equal, or path_max_poses < 1.
  explicit OdometryMessages(const OdometrySettings& settings);

  struct Output {
    nav_msgs::OdometryPtr odom;                       ///< map -> body, twist from the previous frame
    geometry_msgs::TransformStamped map_to_body;      ///< the same pose as tf
    geometry_msgs::TransformStamped body_to_optical;  ///< static; `optical_changed` when it is new
    bool optical_changed = false;
    nav_msgs::PathConstPtr path;  ///< every pose so far (at most path_max_poses); null without make_path
  };
  /// The messages of one frame's pose, stamped with the draw list's header (its frame id names the
  /// optical frame; "camera_optical" when empty).
  Output convert(const EgoFrame& ego, const std_msgs::Header& draws_header);

 private:
  OdometrySettings settings_;
  std::string optical_frame_;  // the optical frame of the last static transform
  nav_msgs::Path path_;
};

/// Flows into recycled messages (32FC2 flow, mono8 mask), each with the header of the frame it
/// starts from (an input decoded by decodeDrawMsgs). take() keeps the messages of the last frame's
/// flows for messages().
class FlowMessagePools : public FlowSink {
 public:
  FlowBuffers take(FlowKind kind, const GroundTruthInput& from) override;
  /// The messages of the flows taken since the last clear(), by kind (null where none was taken).
  FlowMessages& messages(FlowKind kind) { return taken_[static_cast<int>(kind)]; }
  /// Forgets the messages taken (call before each frame).
  void clear();

 private:
  // The flows' messages, recycled. Two flows a frame (and the wide one): with 32, a bag played at
  // 8 frames in flight took fresh 16 MB flow buffers, whose pages the kernel zeroed on first touch
  // (clear_page_erms under takeMessages 0.91 % of the manager; 0.05 % with 64). A pool keeps only
  // as many as were in flight at once.
  ImageMsgPool flow_pool_{64}, visible_pool_{64};
  FlowMessages taken_[3];
};

}  // namespace viper
