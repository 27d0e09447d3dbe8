// The converter between VIPER's release layout (viper_dataset types) and the package's ground-truth
// messages, shared by the player node, viper_to_bag and export_viper (the layout's geometry, which
// it uses, is viper_layout_geometry.h). Frames: the layout's camera is
// OpenGL's (X right, Y up, looking down -Z); messages use REP 103/105 (`map`, camera body x forward /
// y left / z up, optical frame x right / y down / z forward). docs/viper_layout.md.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/dataset/flow_image.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"
#include "viper/dataset/viper_images.h"
#include "viper/dataset/viper_layout_geometry.h"  // the layout's geometry, which the layout's users call
#include "viper/dataset/viper_sequence.h"
#include "viper/ros/conversions/flow_conversions.h"   // flowFromMsg, which the layout's users call
#include "viper/ros/conversions/image_conversions.h"  // imageFromMsg, int32FromMsg

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>
#include <viper/ObjectArray.h>

#include <Eigen/Geometry>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// Topics of the layout's messages, relative to the player's namespace (a bag holds them under
/// "/"): the same names as the capture bridge's and the ground-truth nodes' in replay.launch.
namespace viper_topics {
constexpr const char* kColor = "capture/color/image_raw";
constexpr const char* kCameraInfo = "capture/color/camera_info";
constexpr const char* kSemantic = "ground_truth/semantic";
constexpr const char* kSemanticColor = "ground_truth/semantic_color";
constexpr const char* kInstanceIds = "ground_truth/instance_ids";
constexpr const char* kInstancesViper = "ground_truth/instances_viper";
constexpr const char* kFlowForward = "ground_truth/flow/forward";
constexpr const char* kFlowBackward = "ground_truth/flow/backward";
constexpr const char* kOdom = "ground_truth/odom";
constexpr const char* kPath = "ground_truth/path";
constexpr const char* kBoxes = "ground_truth/boxes";
constexpr const char* kBoxesOptical = "ground_truth/boxes_optical";
constexpr const char* kBoxMarkers = "ground_truth/box_markers";
}  // namespace viper_topics

/// glProjectionFromCameraMatrix (viper_layout_geometry.h) of camera_info's K.
dataset::RowMajor4 glProjectionFromK(const boost::array<double, 9>& K, uint32_t width, uint32_t height,
                                     double near_m, double far_m);

/// Names of the frames of the messages built from the layout.
struct ViperTfFrames {
  std::string map = "map";
  std::string body = "camera";
  std::string optical = "camera_optical";
};

/// Which messages ViperMessageBuilder::build makes.
struct ViperTopicSelection {
  bool color = true, camera_info = true, semantic = true, semantic_color = false, instance_ids = true,
       instances_viper = true, flow_forward = true, flow_backward = true, odom = true, boxes = true,
       boxes_optical = true;
};

/// The messages of one frame of the layout, each null / empty where its input is absent. Every
/// header has the frame's stamp; images are in the optical frame.
struct ViperFrameMessages {
  sensor_msgs::ImagePtr color;            ///< rgb8, from img
  sensor_msgs::CameraInfoPtr camera_info; ///< from the camera row's projection and the frame's size
  sensor_msgs::ImagePtr semantic;         ///< mono8 class ids, from cls (else inst's R channel)
  sensor_msgs::ImagePtr semantic_color;   ///< rgb8 class colors (needs a class table)
  sensor_msgs::ImagePtr instance_ids;     ///< 32SC1, 256 * G + B of inst
  sensor_msgs::ImagePtr instances_viper;  ///< rgb8, inst as it is
  sensor_msgs::ImagePtr flow_forward;     ///< 32FC2, flow (frame -> frame + 1)
  sensor_msgs::ImagePtr flow_backward;    ///< 32FC2, flowbw (frame -> frame - 1)
  nav_msgs::OdometryPtr odom;             ///< map -> body pose, twist from the previous frame
  std::optional<geometry_msgs::TransformStamped> map_to_body;  ///< the same pose as tf
  Box3DArray::Ptr boxes;          ///< in map (needs the camera row)
  Box3DArray::Ptr boxes_optical;  ///< in the optical frame
  std::vector<std::string> problems;  ///< inputs that could not be converted (camera row, boxes)
};

/// Turns frames of one or more sequences into messages. The map frame of a sequence is its first
/// camera row's body frame (VIPER's poses are relative to the first frame; the first pose is the
/// identity whether the file holds relative or absolute views). Box velocities and odometry
/// twists are finite differences over consecutive frames of one sequence.
class ViperMessageBuilder {
 public:
  /// `classes` (may be null) names the classes of boxes and colors semantic_color.
  ViperMessageBuilder(const ViperTfFrames& frames, const ClassTable* classes);
  /// Forgets the previous sequence's origin, pose and boxes.
  void startSequence();
  /// The messages of `frame`, stamped `stamp`.
  ViperFrameMessages build(const dataset::ViperFrame& frame, const ros::Time& stamp,
                           const ViperTopicSelection& selection);
  /// The fixed transform body -> optical frame.
  geometry_msgs::TransformStamped bodyToOptical(const ros::Time& stamp) const;

 private:
  ViperTfFrames frames_;
  const ClassTable* classes_;
  std::optional<Eigen::Isometry3d> origin_inverse_;  // world_from_body of the first row, inverted
  std::optional<EgoPose> last_pose_;
  struct Seen {
    Eigen::Vector3d center_map;
    double time_s;
  };
  std::map<int32_t, Seen> last_boxes_;
};

}  // namespace viper
