#include "viper/ros/conversions/object_conversions.h"

#include <ros/serialization.h>

#include <gtest/gtest.h>

#include <climits>
#include <fstream>
#include <iterator>

namespace viper {
namespace {

ClassTable classes() { return ClassTable::load("config/viper_classes.csv"); }

TEST(ObjectConversions, BoxRoundTrip) {
  OrientedBox b;
  b.center = {1.5, -2, 0.75};
  b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.1, 1).normalized()));
  b.size = {4.2, 1.8, 1.5};
  const Box3D m = toBox3DMsg(b, 17, 24, classes(), Eigen::Vector3d(3, 0, 0));
  EXPECT_EQ(m.class_name, "car");
  EXPECT_EQ(m.id, 17);
  EXPECT_DOUBLE_EQ(m.velocity.linear.x, 3.0);
  const OrientedBox back = fromBox3DMsg(m);
  const auto c0 = b.corners(), c1 = back.corners();
  for (int i = 0; i < 8; ++i) EXPECT_LT((c0[i] - c1[i]).norm(), 1e-12);
}

TEST(ObjectConversions, ObjectsCarryTrackClassDrawsAnd2DBox) {
  TrackedObject t;
  t.track_id = 4;
  t.object.class_id = 26;
  t.object.draws = {3, 4, 9};
  t.object.pixel_count = 12;
  t.object.x_min = 10, t.object.x_max = 13, t.object.y_min = 2, t.object.y_max = 4;
  t.object.world(0, 3) = 7;
  std_msgs::Header h;
  h.frame_id = "camera_optical";
  const ObjectArray a = toObjectArrayMsg({t}, classes(), h);
  ASSERT_EQ(a.objects.size(), 1u);
  EXPECT_EQ(a.objects[0].class_name, "bus");
  EXPECT_EQ(a.objects[0].draws, (std::vector<uint32_t>{3, 4, 9}));
  EXPECT_EQ(a.objects[0].box_2d.width, 4u);
  EXPECT_EQ(a.objects[0].box_2d.height, 3u);
  EXPECT_DOUBLE_EQ(a.objects[0].world_pose.position.x, 7.0);
  EXPECT_DOUBLE_EQ(a.objects[0].world_pose.orientation.w, 1.0);
}

TEST(ObjectConversions, MarkersClearThenOneCubeAndLabelPerBox) {
  Box3DArray boxes;
  boxes.header.frame_id = "map";
  OrientedBox b;
  b.size = {1, 1, 1};
  boxes.boxes = {toBox3DMsg(b, 1, 20, classes(), Eigen::Vector3d::Zero()),
                 toBox3DMsg(b, 2, 24, classes(), Eigen::Vector3d::Zero())};
  const auto m = boxMarkers(boxes, classes());
  ASSERT_EQ(m.markers.size(), 5u);
  EXPECT_EQ(m.markers[0].action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(m.markers[3].type, visualization_msgs::Marker::CUBE);
  EXPECT_NEAR(m.markers[3].color.b, 142 / 255.0, 1e-6);  // car blue
  EXPECT_EQ(m.markers[4].text, "car 2");
}

TEST(ObjectConversions, ObjectsRoundTrip) {
  TrackedObject car, road;
  car.track_id = 12;
  car.object.class_id = 24;
  car.object.is_thing = true;
  car.object.draws = {0, 5};
  car.object.pixel_count = 30;
  car.object.x_min = 4, car.object.y_min = 6, car.object.x_max = 9, car.object.y_max = 10;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, -1, 0.2).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(3, -4, 0.5);
  car.object.world = pose.matrix().cast<float>();
  road.object.class_id = 3;
  road.object.draws = {1};  // stuff: no track, no visible pixels
  const std::vector<TrackedObject> objects = {car, road};
  const std::vector<TrackedObject> back = fromObjectArrayMsg(toObjectArrayMsg(objects, classes(), std_msgs::Header()));
  ASSERT_EQ(back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE("object " + std::to_string(i));
    const FrameObject &a = objects[i].object, &b = back[i].object;
    EXPECT_EQ(back[i].track_id, objects[i].track_id);
    EXPECT_EQ(b.class_id, a.class_id);
    EXPECT_EQ(b.is_thing, a.is_thing);
    EXPECT_EQ(b.draws, a.draws);
    EXPECT_EQ(b.pixel_count, a.pixel_count);
    if (a.pixel_count > 0) {
      EXPECT_EQ(b.x_min, a.x_min);
      EXPECT_EQ(b.y_min, a.y_min);
      EXPECT_EQ(b.x_max, a.x_max);
      EXPECT_EQ(b.y_max, a.y_max);
    }
    EXPECT_LT((b.world - a.world).cwiseAbs().maxCoeff(), 1e-6f) << b.world;
  }
}

// A box's corner is its offset + size - 1, summed in 64 bits and cut at INT_MAX.
void expectBoxOfMessage(const Object& m, const FrameObject& o) {
  const auto corner = [](uint32_t offset, uint32_t size) { return std::min<int64_t>(int64_t(offset) + size, INT_MAX) - 1; };
  EXPECT_EQ(o.x_min, std::min<int64_t>(m.box_2d.x_offset, INT_MAX));
  EXPECT_EQ(o.y_min, std::min<int64_t>(m.box_2d.y_offset, INT_MAX));
  EXPECT_EQ(o.x_max, corner(m.box_2d.x_offset, m.box_2d.width));
  EXPECT_EQ(o.y_max, corner(m.box_2d.y_offset, m.box_2d.height));
}

// Found by the object_messages fuzzer: a 2D box whose offset + size passes INT_MAX overflowed int
// (undefined behaviour; a box with a negative corner in practice).
TEST(ObjectConversions, RegressionFuzzBoxBeyondIntMaxIsCut) {
  std::ifstream in("test/fuzz/regressions/object_messages/box_2d_overflow.bin", std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(bytes.empty());
  ObjectArray msg;
  ros::serialization::IStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  ros::serialization::deserialize(stream, msg);
  ASSERT_FALSE(msg.objects.empty());
  Object far;
  far.pixel_count = 1;
  far.box_2d.x_offset = 0xfffffff0u, far.box_2d.width = 0x20;
  far.box_2d.y_offset = 5, far.box_2d.height = 0xffffffffu;
  msg.objects.push_back(far);
  const std::vector<TrackedObject> objects = fromObjectArrayMsg(msg);
  ASSERT_EQ(objects.size(), msg.objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    SCOPED_TRACE("object " + std::to_string(i));
    if (msg.objects[i].pixel_count > 0) expectBoxOfMessage(msg.objects[i], objects[i].object);
  }
  EXPECT_EQ(objects.back().object.x_min, INT_MAX);
  EXPECT_EQ(objects.back().object.x_max, INT_MAX - 1);
  EXPECT_EQ(objects.back().object.y_max, INT_MAX - 1);
}

}  // namespace
}  // namespace viper
