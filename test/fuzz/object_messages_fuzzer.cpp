// libFuzzer target: arbitrary object, box and odometry messages, ROS-serialized one after another,
// through the converter's message -> core functions (objects, boxes, their rviz markers, checked
// and normalised poses). Class ids outside the table, zero or non-finite quaternions and empty
// boxes must be handled; nothing may crash or throw.
// Seeds: messages the converter builds from tracked objects, oriented boxes and a pose.
#include "fuzz_support.h"
#include "message_input.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <string>

namespace {

const viper::ClassTable& classes() {
  static const viper::ClassTable table = viper::ClassTable::load(VIPER_ROOT "/config/viper_classes.csv");
  return table;
}

}  // namespace

void viper::fuzz::writeSeeds(const std::string& dir) {
  std_msgs::Header header;
  header.stamp = ros::Time(7, 250);
  header.frame_id = "map";
  viper::TrackedObject car;
  car.track_id = 12;
  car.object.draws = {0, 2};
  car.object.class_id = 24;
  car.object.is_thing = true;
  car.object.world(0, 3) = 4;
  car.object.pixel_count = 30;
  car.object.x_min = 1, car.object.y_min = 2, car.object.x_max = 6, car.object.y_max = 7;
  viper::TrackedObject road;
  road.object.draws = {1};
  road.object.class_id = 7;
  viper::OrientedBox box;
  box.center = Eigen::Vector3d(1, 2, 0.5);
  box.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  box.size = Eigen::Vector3d(4, 1.8, 1.5);
  viper::Box3DArray boxes;
  boxes.header = header;
  boxes.boxes = {viper::toBox3DMsg(box, 12, 24, classes(), Eigen::Vector3d(3, 0, 0)),
                 viper::toBox3DMsg(box, 13, 200, classes(), Eigen::Vector3d::Zero())};
  nav_msgs::Odometry odom;
  odom.header = header;
  odom.child_frame_id = "camera";
  odom.pose.pose = viper::toPoseMsg(Eigen::Isometry3d(Eigen::Translation3d(1, 0, 2)));
  std::vector<uint8_t> bytes;
  appendMessage(bytes, viper::toObjectArrayMsg({car, road}, classes(), header));
  appendMessage(bytes, boxes);
  appendMessage(bytes, odom);
  writeBytes(dir + "/objects_boxes_odometry.bin", bytes);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  viper::fuzz::MessageInput input(data, size);
  viper::ObjectArray objects;
  if (!input.next(objects)) return 0;
  if (viper::fromObjectArrayMsg(objects).size() != objects.objects.size()) __builtin_trap();
  viper::Box3DArray boxes;
  if (!input.next(boxes)) return 0;
  for (const viper::Box3D& box : boxes.boxes) (void)viper::fromBox3DMsg(box).corners();
  if (viper::boxMarkers(boxes, classes()).markers.size() != 1 + 2 * boxes.boxes.size()) __builtin_trap();
  nav_msgs::Odometry odom;
  if (!input.next(odom)) return 0;
  Eigen::Isometry3d pose;
  (void)viper::poseFromOdometry(odom, pose);
  (void)viper::fromPoseMsg(odom.pose.pose);
  geometry_msgs::Transform transform;
  transform.translation.x = odom.pose.pose.position.x;
  transform.rotation = odom.pose.pose.orientation;
  (void)viper::fromTransformMsg(transform);
  return 0;
}
