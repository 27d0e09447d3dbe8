#include "viper/ros/ground_truth/ground_truth_conversions.h"

#include <gtest/gtest.h>

namespace viper {
namespace {

ClassTable classes() { return ClassTable::load("config/viper_classes.csv"); }

TEST(GroundTruthConversions, BoxRoundTrip) {
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

TEST(GroundTruthConversions, ObjectsCarryTrackClassDrawsAnd2DBox) {
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

TEST(GroundTruthConversions, MarkersClearThenOneCubeAndLabelPerBox) {
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

TEST(GroundTruthConversions, FrameFromDrawMessagesChecksTheImage) {
  DrawList dl;
  dl.header.stamp = ros::Time(5, 0);
  dl.draws.resize(2);
  dl.draws[1].index = 1;
  std::vector<int32_t> ids = {0, 1, 2, 2, 1, 0};
  std_msgs::Header h = dl.header;
  sensor_msgs::Image img = imageMsg(h, 3, 2, "32SC1", 4, ids.data());
  CaptureFrame f;
  EXPECT_EQ(frameFromDrawMsgs(dl, img, f), "");
  EXPECT_EQ(f.width, 3u);
  EXPECT_EQ(f.draw_ids[2], 2u);
  EXPECT_DOUBLE_EQ(f.time_s, 5.0);
  sensor_msgs::Image wrong = img;
  wrong.encoding = "mono8";
  EXPECT_NE(frameFromDrawMsgs(dl, wrong, f).find("encoding 'mono8'"), std::string::npos);
  wrong = img;
  wrong.data.pop_back();
  EXPECT_NE(frameFromDrawMsgs(dl, wrong, f).find("sizes disagree"), std::string::npos);
  wrong = img;
  wrong.header.stamp = ros::Time(6, 0);
  EXPECT_NE(frameFromDrawMsgs(dl, wrong, f).find("different stamps"), std::string::npos);
}

}  // namespace
}  // namespace viper
