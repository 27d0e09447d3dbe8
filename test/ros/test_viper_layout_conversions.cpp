// The converter between VIPER's layout and the ground-truth messages, and the exporter, without a
// roscore: camera poses and projections both ways, boxes both ways, image messages of every layout
// (padding, byte order, bgr8), the messages of one frame, and the exporter's pairing and camera
// sources.
#include "../common/temp_dir.h"

#include "viper/dataset/viper_layout.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/dataset/viper_exporter.h"
#include "viper/ros/dataset/viper_layout_conversions.h"

#include <gtest/gtest.h>

#include <boost/make_shared.hpp>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace {

using namespace viper;
namespace fs = std::filesystem;

dataset::RowMajor4 someView(double yaw, const Eigen::Vector3d& p) {
  // world_from_gl = T(p) * Ry(yaw) * Rx(0.1); view is its inverse.
  Eigen::Isometry3d world_from_gl = Eigen::Isometry3d::Identity();
  world_from_gl.translation() = p;
  world_from_gl.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                               .toRotationMatrix();
  return toRowMajor(Eigen::Matrix4d(world_from_gl.inverse().matrix()));
}

TEST(ViperLayoutConversions, BodyPoseAgreesWithTheOdometryNodesConvention) {
  const dataset::RowMajor4 view = someView(0.3, {1, 2, 3});
  const Eigen::Isometry3d ours = worldFromBody(view);
  const Eigen::Isometry3d odometry_node = egoPoseFromView(toGlMatrix(view), 0.0).map_from_body;
  EXPECT_LT((ours.matrix() - odometry_node.matrix()).cwiseAbs().maxCoeff(), 1e-6);
  // And back.
  const dataset::RowMajor4 back = viewFromBodyPose(ours);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(back[i], view[i], 1e-12) << i;
}

TEST(ViperLayoutConversions, RelativeViewsStartAtIdentityAndKeepRelativePoses) {
  const dataset::RowMajor4 a = someView(0.3, {1, 2, 3}), b = someView(0.5, {4, 2, -7});
  const dataset::RowMajor4 ra = relativeView(a, a), rb = relativeView(b, a);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(ra[i], dataset::identity4()[i], 1e-12);
  const Eigen::Isometry3d expected = worldFromBody(a).inverse() * worldFromBody(b);
  const Eigen::Isometry3d got = worldFromBody(ra).inverse() * worldFromBody(rb);
  EXPECT_LT((expected.matrix() - got.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  dataset::RowMajor4 scaled = a;
  scaled[0] *= 2;
  EXPECT_THROW(worldFromBody(scaled), std::invalid_argument);
  EXPECT_THROW(relativeView(b, scaled), std::invalid_argument);
}

TEST(ViperLayoutConversions, ProjectionFromKIsTheInverseOfIntrinsicsFromGlProjection) {
  // Zero skew: intrinsicsFromGlProjection negates the unsigned width in its skew term, so a
  // skewed projection does not come back (reported; no usual projection has skew).
  boost::array<double, 9> K{{500.5, 0, 319.25, 0, 501.5, 241.75, 0, 0, 1}};
  const dataset::RowMajor4 p = glProjectionFromK(K, 640, 480, 0.1, 100);
  const PinholeIntrinsics k = intrinsicsFromGlProjection(toGlMatrix(p), 640, 480);
  EXPECT_NEAR(k.fx, 500.5, 1e-3);
  EXPECT_NEAR(k.fy, 501.5, 1e-3);
  EXPECT_NEAR(k.cx, 319.25, 1e-3);
  EXPECT_NEAR(k.cy, 241.75, 1e-3);
  EXPECT_NEAR(k.skew, 0, 1e-3);
  const DepthLinearizer depth(toGlMatrix(p));
  EXPECT_NEAR(depth.toMetres(0.0f), 0.1, 1e-5);
  K[8] = 2;
  EXPECT_THROW(glProjectionFromK(K, 640, 480, 0.1, 100), std::invalid_argument);
  K[8] = 1;
  EXPECT_THROW(glProjectionFromK(K, 640, 480, 1, 1), std::invalid_argument);
}

TEST(ViperLayoutConversions, BoxRowsRoundTripThroughTheOpticalFrame) {
  OrientedBox box;
  box.center = {1.5, -0.25, 12};
  box.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1, 0.1).normalized()));
  box.size = {4.2, 1.8, 1.5};
  const dataset::ViperBoxRow row = viperBoxRow(box, 24, 70000, {{1, 2, 3, 4}});
  EXPECT_EQ(row.instance_id, 70000);
  EXPECT_DOUBLE_EQ(row.box_3d[0], -2.1);
  EXPECT_DOUBLE_EQ(row.box_3d[5], 0.75);
  // The matrix maps the model centre to the box centre in OpenGL camera axes (y up, z back).
  EXPECT_NEAR(row.model_to_camera[3], 1.5, 1e-12);
  EXPECT_NEAR(row.model_to_camera[7], 0.25, 1e-12);
  EXPECT_NEAR(row.model_to_camera[11], -12, 1e-12);
  Eigen::Isometry3d optical_from_gl = Eigen::Isometry3d::Identity();
  optical_from_gl.linear() = opticalFromGlCamera();
  const OrientedBox back = boxInGlCamera(row).transformed(optical_from_gl);
  EXPECT_LT((back.center - box.center).norm(), 1e-12);
  EXPECT_LT((back.size - box.size).norm(), 1e-12);
  EXPECT_LT(back.orientation.angularDistance(box.orientation), 1e-9);
  // A scaled, off-centre model box (as VIPER's own files have).
  dataset::ViperBoxRow scaled = row;
  scaled.box_3d = {{0, 0, 0, 2, 1, 4}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) scaled.model_to_camera[4 * r + c] *= 0.5;
  const OrientedBox s = boxInGlCamera(scaled);
  EXPECT_LT((s.size - Eigen::Vector3d(1, 0.5, 2)).norm(), 1e-12);
  scaled.model_to_camera[0] = scaled.model_to_camera[4] = scaled.model_to_camera[8] = 0;
  EXPECT_THROW(boxInGlCamera(scaled), std::invalid_argument);
}

TEST(ViperLayoutConversions, ImageMessagesOfEveryLayout) {
  std_msgs::Header h;
  sensor_msgs::Image bgr;
  bgr.encoding = "bgr8", bgr.width = 2, bgr.height = 2, bgr.step = 8;  // 2 bytes of padding per row
  bgr.data = {1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 9, 10, 11, 12, 0, 0};
  dataset::Image8 rgb;
  EXPECT_EQ(imageFromMsg(bgr, "rgb8", rgb), "");
  EXPECT_EQ(rgb.data, (std::vector<uint8_t>{3, 2, 1, 6, 5, 4, 9, 8, 7, 12, 11, 10}));
  bgr.data.pop_back();
  EXPECT_NE(imageFromMsg(bgr, "rgb8", rgb).find("data has 15 bytes"), std::string::npos);
  sensor_msgs::Image mono = imageMsg(h, 3, 1, "mono8", 1, std::vector<uint8_t>{1, 2, 3}.data());
  EXPECT_NE(imageFromMsg(mono, "rgb8", rgb).find("encoding is 'mono8'"), std::string::npos);

  const std::vector<int32_t> ids = {1, 70000, -1};
  sensor_msgs::Image big = imageMsg(h, 3, 1, "32SC1", 4, ids.data());
  big.is_bigendian = 1;
  for (size_t i = 0; i < 3; ++i) std::reverse(big.data.begin() + 4 * i, big.data.begin() + 4 * i + 4);
  std::vector<int32_t> back;
  EXPECT_EQ(int32FromMsg(big, back), "");
  EXPECT_EQ(back, ids);
  const std::vector<float> uv = {0.5f, -1.25f, NAN, 3.0f};
  dataset::FlowImage flow;
  EXPECT_EQ(flowFromMsg(imageMsg(h, 2, 1, "32FC2", 8, uv.data()), flow), "");
  EXPECT_EQ(flow.uv[1], -1.25f);
  EXPECT_TRUE(std::isnan(flow.uv[2]));
  EXPECT_NE(flowFromMsg(mono, flow).find("expected 32FC2"), std::string::npos);
}

TEST(ViperLayoutConversions, InstanceBoxesAreTightAndInclusive) {
  const std::vector<int32_t> ids = {0, 5, 5, 0,  //
                                    0, 0, 5, 9,  //
                                    9, 0, 0, 0};
  const auto boxes = instanceBoxes(ids.data(), 4, 3);
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes.at(5), (std::array<double, 4>{{1, 0, 2, 1}}));
  EXPECT_EQ(boxes.at(9), (std::array<double, 4>{{0, 1, 3, 2}}));
}

TEST(ViperLayoutConversions, FrameMessagesUseTheFirstRowAsMapAndFallBackToInstClasses) {
  dataset::ViperFrame f;
  f.frame = 4, f.width = 2, f.height = 1;
  f.inst = dataset::Image8{2, 1, 3, {24, 1, 2, 3, 0, 0}};
  f.camera = dataset::ViperCameraRow{4, glProjectionFromK({{2, 0, 0.5, 0, 2, 0, 0, 0, 1}}, 2, 1, 0.1, 10),
                                     someView(0.2, {0, 0, 5})};
  ViperMessageBuilder builder(ViperTfFrames{}, nullptr);
  ViperTopicSelection all;
  const ViperFrameMessages m = builder.build(f, ros::Time(10.0), all);
  EXPECT_TRUE(m.problems.empty());
  ASSERT_TRUE(m.semantic && m.instance_ids && m.instances_viper && m.odom && m.camera_info && m.map_to_body);
  EXPECT_EQ(m.semantic->data, (std::vector<uint8_t>{24, 3})) << "no cls: the classes of inst";
  EXPECT_FALSE(m.color || m.flow_forward || m.boxes);
  EXPECT_NEAR(m.odom->pose.pose.position.x, 0, 1e-12) << "the first row is the map's origin";
  EXPECT_NEAR(m.odom->pose.pose.orientation.w, 1, 1e-12);
  EXPECT_NEAR(m.camera_info->K[0], 2, 1e-6);
  dataset::ViperFrame g = f;
  g.frame = 5;
  g.camera->view = someView(0.2, {0, 0, 4});  // 1 m forward (GL -Z, turned 0.2 rad about Y)
  g.boxes = std::vector<dataset::ViperBoxRow>{viperBoxRow(OrientedBox{}, 24, 3, {{0, 0, 0, 0}})};
  const ViperFrameMessages n = builder.build(g, ros::Time(11.0), all);
  const Eigen::Isometry3d expected = worldFromBody(f.camera->view).inverse() * worldFromBody(g.camera->view);
  EXPECT_LT((fromPoseMsg(n.odom->pose.pose).matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(expected.translation().norm(), 1, 1e-9);
  EXPECT_NEAR(n.odom->twist.twist.linear.x, -(expected.inverse().translation()).x(), 1e-9) << "1 s between the frames";
  ASSERT_TRUE(n.boxes && n.boxes_optical);
  EXPECT_EQ(n.boxes->header.frame_id, "map");
  EXPECT_EQ(n.boxes_optical->header.frame_id, "camera_optical");
  EXPECT_EQ(n.boxes->boxes[0].class_name, "class_24") << "no class table";
  builder.startSequence();
  EXPECT_NEAR(builder.build(g, ros::Time(12.0), all).odom->pose.pose.position.x, 0, 1e-12) << "a new sequence, a new map";
}

TEST(ViperExporter, PairsPartsAndReportsWhatIsMissing) {
  const test::TempDir dir("viper_conv_");
  ViperExportOptions o;
  o.root = dir.path().string();
  o.camera = CameraSource::kOdometry;
  o.relative_poses = false;
  ViperExporter e(o);
  std_msgs::Header h;
  const std::vector<uint8_t> classes = {24, 3};
  const std::vector<int32_t> ids = {70001, 0};
  auto semantic = boost::make_shared<sensor_msgs::Image>(imageMsg(h, 2, 1, "mono8", 1, classes.data()));
  auto instance_ids = boost::make_shared<sensor_msgs::Image>(imageMsg(h, 2, 1, "32SC1", 4, ids.data()));
  EXPECT_EQ(e.addSemantic(0, semantic), "");
  EXPECT_NE(e.addInstanceIds(0, instance_ids).find("outside 0..65535"), std::string::npos);
  const dataset::Image8 inst = dataset::readViperInstanceImage(dataset::viperFramePath(o.root, "train", "inst", "001", 0, "png"));
  EXPECT_EQ(inst.data, (std::vector<uint8_t>{24, 0x11, 0x71, 3, 0, 0})) << "70001 mod 65536 = 0x1171";
  EXPECT_EQ(e.addSemantic(1, semantic), "");  // its instance ids never come

  // Boxes wait for the objects' 2D boxes.
  auto boxes = boost::make_shared<Box3DArray>();
  OrientedBox b;
  b.center = {0, 0, 5};
  b.size = {1, 1, 1};
  boxes->boxes.push_back(toBox3DMsg(b, 70001, 24, ClassTable{}, Eigen::Vector3d::Zero()));
  EXPECT_EQ(e.addBoxesOptical(0, boxes), "");
  EXPECT_FALSE(fs::exists(dataset::viperFramePath(o.root, "train", "bb", "001", 0, "csv")));
  auto objects = boost::make_shared<ObjectArray>();
  objects->objects.resize(1);
  objects->objects[0].track_id = 70001;
  objects->objects[0].box_2d.x_offset = 3, objects->objects[0].box_2d.y_offset = 4;
  objects->objects[0].box_2d.width = 2, objects->objects[0].box_2d.height = 1;
  EXPECT_EQ(e.addObjects(0, objects), "");
  std::vector<std::string> problems;
  const auto rows = dataset::readViperBoxesCsv(dataset::viperFramePath(o.root, "train", "bb", "001", 0, "csv"), problems);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].box_2d, (std::array<double, 4>{{3, 4, 4, 4}}));
  EXPECT_EQ(rows[0].instance_id, 70001);

  // Camera rows from odometry + camera_info, in either order.
  nav_msgs::Odometry odom;
  odom.pose.pose.orientation.w = 1;
  odom.pose.pose.position.x = 2;
  sensor_msgs::CameraInfo info;
  info.width = 2, info.height = 1;
  info.K = {{2, 0, 0.5, 0, 2, 0, 0, 0, 1}};
  EXPECT_EQ(e.addOdometry(0, odom), "");
  EXPECT_EQ(e.addCameraInfo(0, info), "");
  EXPECT_EQ(e.addCameraInfo(1, info), "");
  EXPECT_EQ(e.addOdometry(1, odom), "");
  EXPECT_EQ(e.addOdometry(2, odom), "");  // its camera_info never comes
  info.K[0] = 0;
  EXPECT_NE(e.addCameraInfo(3, info), "");

  // Bad messages are skipped with a reason.
  sensor_msgs::Image wrong = imageMsg(h, 2, 1, "rgb8", 3, std::vector<uint8_t>(6).data());
  EXPECT_NE(e.addFlow(0, boost::make_shared<sensor_msgs::Image>(wrong), false).find("expected 32FC2"), std::string::npos);
  EXPECT_NE(e.addColor(0, *semantic).find("expected rgb8"), std::string::npos);

  const std::vector<std::string> notes = e.finish();
  auto noted = [&](const std::string& s) {
    return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(s) != std::string::npos; });
  };
  EXPECT_TRUE(noted("frame 1: semantic without instance ids: no inst file"));
  EXPECT_TRUE(noted("frame 2: odometry without camera_info: no camera row"));
  EXPECT_EQ(e.stats().skipped, 3u);
  EXPECT_EQ(e.stats().inst, 1u);
  EXPECT_EQ(e.stats().cls, 2u);
  EXPECT_EQ(e.stats().bb, 1u);
  EXPECT_EQ(e.stats().camera_rows, 2u);
  const auto camera = dataset::readViperCameraCsv(dataset::viperCameraPath(o.root, "train", "001"), problems);
  ASSERT_EQ(camera.size(), 2u);
  EXPECT_TRUE(problems.empty());
  EXPECT_NEAR(worldFromBody(camera.at(1).view).translation().x(), 2, 1e-12) << "absolute poses kept";
  EXPECT_NEAR(intrinsicsFromGlProjection(toGlMatrix(camera.at(0).projection), 2, 1).fx, 2, 1e-6);
}

TEST(ViperExporter, WritesRelativePosesFromDraws) {
  const test::TempDir dir("viper_conv_");
  ViperExportOptions o;
  o.root = dir.path().string();
  ViperExporter e(o);
  auto drawList = [](const dataset::RowMajor4& view) {
    DrawList d;
    d.draws.resize(1);
    Draw& draw = d.draws[0];
    draw.matrix_flags = kHasView | kHasProjection;
    const GlMatrix v = toGlMatrix(view), p = toGlMatrix(glProjectionFromK({{2, 0, 0.5, 0, 2, 0, 0, 0, 1}}, 2, 1, 0.1, 10));
    for (int i = 0; i < 16; ++i) draw.view[i] = v.data()[i], draw.projection[i] = p.data()[i];
    return d;
  };
  const dataset::RowMajor4 a = someView(0.3, {1, 2, 3}), b = someView(0.4, {1, 2, 1});
  EXPECT_EQ(e.addDraws(10, drawList(a)), "");
  EXPECT_EQ(e.addDraws(11, drawList(b)), "");
  e.finish();
  std::vector<std::string> problems;
  const auto camera = dataset::readViperCameraCsv(dataset::viperCameraPath(o.root, "train", "001"), problems);
  ASSERT_EQ(camera.size(), 2u);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(camera.at(10).view[i], dataset::identity4()[i], 1e-6) << i;
  const Eigen::Isometry3d expected = worldFromBody(a).inverse() * worldFromBody(b);
  const Eigen::Isometry3d got = worldFromBody(camera.at(10).view).inverse() * worldFromBody(camera.at(11).view);
  EXPECT_LT((got.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-5);
}

}  // namespace
