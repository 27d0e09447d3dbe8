// KITTI object detection and tracking labels (label_2 lines, tracking label lines) and calib files,
// in KITTI's camera conventions (camera x right, y down, z forward: the optical frame; location =
// the bottom centre of the box; rotation_y around the camera's Y axis), from oriented boxes in the
// camera's optical frame. docs/training_formats.md. ROS-free (Eigen).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>

namespace viper::dataset {

/// One object of a KITTI label file.
struct KittiObject {
  std::string type = "DontCare";   ///< Car, Van, Truck, Pedestrian, Person_sitting, Cyclist, Tram, Misc, DontCare
  double truncated = 0.0;          ///< 0..1, share of the object outside the image
  int occluded = 3;                ///< 0 fully visible, 1 partly, 2 largely occluded, 3 unknown
  double alpha = 0.0;              ///< observation angle, -pi..pi
  std::array<double, 4> box{{0, 0, 0, 0}};  ///< 2D box x1 y1 x2 y2, pixels
  double height = 0.0, width = 0.0, length = 0.0;  ///< metres
  Eigen::Vector3d location = Eigen::Vector3d::Zero();  ///< bottom centre in the camera frame, metres
  double rotation_y = 0.0;         ///< around the camera's Y, -pi..pi; 0 = facing the camera's x axis
};

/// The KITTI type of a VIPER class id (config/viper_classes.csv): car -> Car, van -> Van,
/// truck and bus -> Truck, person -> Pedestrian, bicycle and motorcycle -> Cyclist, train -> Tram,
/// trailer -> Misc, every other class -> DontCare (docs/training_formats.md says why).
std::string kittiTypeOfViperClass(int viper_class_id);

/// The KITTI box of an oriented box given in the camera's optical frame (centre, object axes as a
/// rotation, full size along those axes). The object axis closest to the camera's vertical (y)
/// gives the height; of the other two, the longer gives the length and the heading (that axis's
/// positive direction projected on the camera's x-z plane: which end is the front is not known);
/// location = centre + height / 2 along +y (KITTI's y points down, the camera taken as level);
/// rotation_y = atan2(-heading_z, heading_x); alpha = rotation_y - atan2(x, z) of the centre,
/// both wrapped to -pi..pi. Type, 2D box, truncation and occlusion are left for the caller.
KittiObject kittiObjectOfBox(const Eigen::Vector3d& center, const Eigen::Quaterniond& orientation,
                             const Eigen::Vector3d& size);

/// A label_2 line: "type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y" with KITTI's
/// precision (2 decimals; truncated as 2 decimals, occluded an integer), no trailing newline.
std::string kittiLabelLine(const KittiObject& object);

/// A tracking label line: "frame track_id " + kittiLabelLine (KITTI tracking; track id -1 for
/// DontCare regions).
std::string kittiTrackingLine(uint32_t frame, int64_t track_id, const KittiObject& object);

/// A calib file of the object benchmark for a camera of projection `P` (3x4, pixels, the optical
/// frame): P0..P3 all `P` (one camera), R0_rect the identity, Tr_velo_to_cam and Tr_imu_to_velo
/// the identity's 3x4 (no lidar, no IMU: the camera frame stands for both), each a line
/// "NAME: v v v ..." as KITTI writes them (%.12e).
std::string kittiCalibText(const Eigen::Matrix<double, 3, 4>& P);

}  // namespace viper::dataset
