// Converter round trips (core -> msg -> core) and the image/camera-info messages of a frame.
#include "viper/ros/conversions/frame_conversions.h"

#include "sample_header.h"

#include "../../capture/test_capture_stream_frames.h"
#include "../../common/gl_matrices.h"

#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstring>
#include <optional>

#include <boost/make_shared.hpp>

namespace viper {
namespace {

GlMatrix numberedMatrix(float base) {
  GlMatrix m;
  for (int i = 0; i < 16; ++i) m.data()[i] = base + 0.25f * i;  // distinct entries expose transposes
  return m;
}

CaptureFrame sampleFrame() {
  CaptureFrame f;
  f.number = 41;
  f.time_s = 3.25;
  f.condition = "rain";
  f.width = 3;
  f.height = 2;
  f.color_rgb = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18};
  f.depth_window = {0.5f, 0.9f, 1.0f, 0.2f, 0.3f, 1.0f};
  f.draw_ids = {1, 2, 0, 2, 2, 0};
  f.primitive_ids = {0, 7, 99, 3, 4, 5};
  DrawRecord a;
  a.index = 0;
  a.mesh_key = 0x1234567890abcdefULL;
  a.vertex_buffer_key = 11;
  a.index_buffer_key = 12;
  a.program_key = 0xfedcba9876543210ULL;
  a.texture_keys = {21, 22, 23};
  a.matrix_flags = kHasWorld | kHasView | kHasProjection;
  a.world = numberedMatrix(1.0f);
  a.view = numberedMatrix(-7.0f);
  a.projection = numberedMatrix(100.0f);
  a.primitive_mode = 4;
  a.primitive_count = 12;
  a.visible_pixels = 1;
  DrawRecord b = a;
  b.index = 1;
  b.mesh_key = 77;
  b.texture_keys.clear();
  b.matrix_flags = kHasProjection;
  b.visible_pixels = 3;
  b.deformed_clip_xyzw = {0.1f, -0.2f, 0.3f, 1.0f, 4.0f, 5.0f, -6.5f, 2.0f};
  f.draws = {a, b};
  MeshRecord mesh;
  mesh.key = 77;
  mesh.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0.5f};
  mesh.indices = {0, 1, 2};
  f.new_meshes = {mesh};
  return f;
}

using test::sampleHeader;

TEST(FrameConversions, DrawListRoundTrip) {
  const CaptureFrame frame = sampleFrame();
  const DrawList msg = toDrawListMsg(frame, sampleHeader());
  EXPECT_EQ(msg.header.stamp, sampleHeader().stamp);
  EXPECT_EQ(msg.header.frame_id, "camera_optical");
  ASSERT_EQ(msg.draws.size(), 2u);
  // The message stores the matrices column-major, as OpenGL does: element (row 1, col 0) is index 1.
  EXPECT_FLOAT_EQ(msg.draws[0].world[1], frame.draws[0].world(1, 0));
  EXPECT_FLOAT_EQ(msg.draws[0].world[4], frame.draws[0].world(0, 1));
  EXPECT_EQ(msg.draws[0].matrix_flags, Draw::HAS_WORLD | Draw::HAS_VIEW | Draw::HAS_PROJECTION);

  CaptureFrame back;
  fromDrawListMsg(msg, back);
  EXPECT_EQ(back.number, frame.number);
  EXPECT_EQ(back.condition, frame.condition);
  ASSERT_EQ(back.draws.size(), frame.draws.size());
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    SCOPED_TRACE("draw " + std::to_string(i));
    test::expectDrawEq(frame.draws[i], back.draws[i]);
  }
}

TEST(FrameConversions, MeshRoundTrip) {
  const MeshRecord mesh = sampleFrame().new_meshes[0];
  const MeshRecord back = fromMeshMsg(toMeshMsg(mesh));
  EXPECT_EQ(back.key, mesh.key);
  EXPECT_EQ(back.positions_xyz, mesh.positions_xyz);
  EXPECT_EQ(back.indices, mesh.indices);
}

// The bridge sends its whole mesh store again with every new mesh: a node converts only the meshes
// its registry does not already hold as they are.
TEST(FrameConversions, AMeshStoreSentAgainGivesOnlyWhatIsNewOrChanged) {
  MeshRecord first = sampleFrame().new_meshes[0], second = first;
  second.key = 78;
  second.positions_xyz[8] = 2.0f;
  MeshStore store;
  store.meshes = {toMeshMsg(first)};
  std::vector<std::string> problems;
  MeshRegistry known;
  const std::vector<MeshRecord> once = fromMeshStoreMsg(store, problems, &known);
  ASSERT_EQ(once.size(), 1u) << "an empty registry holds nothing";
  known.add(once);
  EXPECT_TRUE(fromMeshStoreMsg(store, problems, &known).empty()) << "the same store again";
  store.meshes.push_back(toMeshMsg(second));
  std::vector<MeshRecord> again = fromMeshStoreMsg(store, problems, &known);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].key, 78u);
  known.add(again);
  // A key the registry holds with other positions or indices is converted again (and replaced).
  store.meshes[0].positions_xyz[0] = 0.5f;
  store.meshes[1].indices = {2, 1, 0};
  again = fromMeshStoreMsg(store, problems, &known);
  ASSERT_EQ(again.size(), 2u);
  EXPECT_EQ(again[0].positions_xyz[0], 0.5f);
  EXPECT_EQ(again[1].indices, (std::vector<uint32_t>{2, 1, 0}));
  EXPECT_EQ(fromMeshStoreMsg(store, problems).size(), 2u) << "without a registry, every mesh";
  EXPECT_TRUE(problems.empty());
}

// A frame converted into again (a node's frame kept from message to message) holds the new draws
// only, whatever it held before: fewer draws, other texture keys, no deformed positions.
TEST(FrameConversions, DrawListIntoAFrameThatHeldAnother) {
  const CaptureFrame frame = sampleFrame();
  CaptureFrame reused;
  CaptureFrame bigger = frame;
  bigger.draws.push_back(frame.draws[1]);
  bigger.draws[0].texture_keys = {1, 2, 3, 4};
  bigger.draws[0].deformed_clip_xyzw = {1, 2, 3, 4};
  fromDrawListMsg(toDrawListMsg(bigger, sampleHeader()), reused);
  ASSERT_EQ(reused.draws.size(), 3u);
  fromDrawListMsg(toDrawListMsg(frame, sampleHeader()), reused);
  ASSERT_EQ(reused.draws.size(), frame.draws.size());
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    SCOPED_TRACE("draw " + std::to_string(i));
    test::expectDrawEq(frame.draws[i], reused.draws[i]);
  }
}

TEST(FrameConversions, ImagesHaveEncodingsSizesAndValues) {
  const CaptureFrame frame = sampleFrame();
  const std_msgs::Header h = sampleHeader();

  const sensor_msgs::Image color = colorImage(frame, h);
  EXPECT_EQ(color.encoding, sensor_msgs::image_encodings::RGB8);
  EXPECT_EQ(color.width, 3u);
  EXPECT_EQ(color.height, 2u);
  EXPECT_EQ(color.step, 9u);
  EXPECT_EQ(color.data, frame.color_rgb);
  EXPECT_EQ(color.header.stamp, h.stamp);

  const std::vector<float> depth_m = {1.5f, 2.0f, NAN, 0.5f, 0.25f, NAN};
  const sensor_msgs::Image depth = depthImage(frame, depth_m, h);
  EXPECT_EQ(depth.encoding, sensor_msgs::image_encodings::TYPE_32FC1);
  EXPECT_EQ(depth.step, 12u);
  std::vector<float> depth_back(6);
  std::memcpy(depth_back.data(), depth.data.data(), 24);
  EXPECT_EQ(depth_back[0], 1.5f);
  EXPECT_EQ(depth_back[4], 0.25f);
  EXPECT_TRUE(std::isnan(depth_back[5]));

  const sensor_msgs::Image ids = drawIdImage(frame, h);
  EXPECT_EQ(ids.encoding, sensor_msgs::image_encodings::TYPE_32SC1);
  std::vector<int32_t> ids_back(6);
  std::memcpy(ids_back.data(), ids.data.data(), 24);
  EXPECT_EQ(ids_back, (std::vector<int32_t>{1, 2, 0, 2, 2, 0}));

  const sensor_msgs::Image prims = primitiveIdImage(frame, h);
  EXPECT_EQ(prims.encoding, sensor_msgs::image_encodings::TYPE_32SC1);
  std::vector<int32_t> prims_back(6);
  std::memcpy(prims_back.data(), prims.data.data(), 24);
  EXPECT_EQ(prims_back, (std::vector<int32_t>{0, 7, -1, 3, 4, -1}));  // -1 where no draw owns the pixel
}

// Many pixels (the mask goes four at a time, the rest one by one): -1 exactly where no draw is,
// every other primitive id unchanged, also ids and primitive ids of the top bit.
TEST(FrameConversions, PrimitiveIdsMaskedWhereNoDrawIs) {
  CaptureFrame frame = sampleFrame();
  frame.width = 37, frame.height = 3;
  const size_t n = frame.pixelCount();
  frame.draw_ids.resize(n), frame.primitive_ids.resize(n);
  for (size_t p = 0; p < n; ++p) {
    frame.draw_ids[p] = (p * 7 % 5 == 0) ? 0 : (p % 2 ? 1 : 0x80000000u);
    frame.primitive_ids[p] = static_cast<uint32_t>(p * 2654435761u);
  }
  const sensor_msgs::Image prims = primitiveIdImage(frame, sampleHeader());
  std::vector<int32_t> back(n);
  ASSERT_EQ(prims.data.size(), 4 * n);
  std::memcpy(back.data(), prims.data.data(), 4 * n);
  for (size_t p = 0; p < n; ++p)
    EXPECT_EQ(back[p], frame.draw_ids[p] == 0 ? -1 : static_cast<int32_t>(frame.primitive_ids[p])) << "pixel " << p;
}

TEST(FrameConversions, ImageSizeMismatchThrows) {
  CaptureFrame frame = sampleFrame();
  frame.color_rgb.pop_back();
  frame.draw_ids.push_back(1);
  EXPECT_THROW(colorImage(frame, sampleHeader()), std::invalid_argument);
  EXPECT_THROW(drawIdImage(frame, sampleHeader()), std::invalid_argument);
  EXPECT_THROW(primitiveIdImage(frame, sampleHeader()), std::invalid_argument);
  EXPECT_THROW(depthImage(frame, std::vector<float>(5), sampleHeader()), std::invalid_argument);
}

TEST(FrameConversions, FrameFromDrawMessagesChecksTheImage) {
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
  EXPECT_NE(frameFromDrawMsgs(dl, wrong, f).find("encoding is 'mono8'"), std::string::npos);
  wrong = img;
  wrong.data.pop_back();
  EXPECT_NE(frameFromDrawMsgs(dl, wrong, f).find("sizes disagree"), std::string::npos);
  wrong = img;
  wrong.header.stamp = ros::Time(6, 0);
  EXPECT_NE(frameFromDrawMsgs(dl, wrong, f).find("different stamps"), std::string::npos);
}

// A frame with real cameras, as a capture holds it: draw 0 placed with view and projection, draw 1
// deformed with its own projection; pixels of no draw at the far plane.
CaptureFrame cameraFrame() {
  CaptureFrame f = sampleFrame();
  f.draws[0].projection = test::glPerspective(1.0, 1.5, 0.1, 100.0);
  f.draws[0].view = GlMatrix::Identity();
  f.draws[0].view(2, 3) = -2.0f;
  f.draws[1].projection = test::glPerspective(0.8, 1.5, 0.5, 300.0);
  f.time_s = 12.5;
  return f;
}

TEST(FrameConversions, WholeFrameRoundTrip) {
  const CaptureFrame frame = cameraFrame();
  std_msgs::Header header = sampleHeader();
  header.stamp = ros::Time(frame.time_s);
  MeshStoreAccumulator store;
  const FrameMessages messages = frameMessages(frame, header, store);
  EXPECT_EQ(messages.camera_problem, "");
  ASSERT_TRUE(messages.mesh_store);

  CaptureFrame back;
  std::vector<float> depth_m;
  ASSERT_EQ(frameFromMessages(messages, back, &depth_m), "");
  EXPECT_EQ(back.number, frame.number);
  EXPECT_DOUBLE_EQ(back.time_s, frame.time_s);
  EXPECT_EQ(back.condition, frame.condition);
  EXPECT_EQ(back.width, frame.width);
  EXPECT_EQ(back.height, frame.height);
  EXPECT_EQ(back.color_rgb, frame.color_rgb);
  EXPECT_EQ(back.draw_ids, frame.draw_ids);
  ASSERT_EQ(back.draws.size(), frame.draws.size());
  for (size_t i = 0; i < frame.draws.size(); ++i) test::expectDrawEq(frame.draws[i], back.draws[i]);
  ASSERT_EQ(back.primitive_ids.size(), frame.primitive_ids.size());
  ASSERT_EQ(back.depth_window.size(), frame.depth_window.size());
  for (size_t p = 0; p < frame.pixelCount(); ++p) {
    SCOPED_TRACE("pixel " + std::to_string(p));
    if (frame.draw_ids[p] != 0) {  // else meaningless
      EXPECT_EQ(back.primitive_ids[p], frame.primitive_ids[p]);
    }
    EXPECT_NEAR(back.depth_window[p], frame.depth_window[p], 1e-6f);
    EXPECT_EQ(std::isnan(depth_m[p]), frame.depth_window[p] == 1.0f);
  }
  ASSERT_EQ(back.new_meshes.size(), 1u);
  EXPECT_EQ(back.new_meshes[0].key, frame.new_meshes[0].key);
  EXPECT_EQ(back.new_meshes[0].positions_xyz, frame.new_meshes[0].positions_xyz);
  EXPECT_EQ(back.new_meshes[0].indices, frame.new_meshes[0].indices);

  // And again: the frame that came back gives the same messages.
  MeshStoreAccumulator store2;
  const FrameMessages again = frameMessages(back, header, store2);
  EXPECT_EQ(again.color->data, messages.color->data);
  EXPECT_EQ(again.draw_ids->data, messages.draw_ids->data);
  EXPECT_EQ(again.primitive_ids->data, messages.primitive_ids->data);
  EXPECT_EQ(*again.draws, *messages.draws);
  EXPECT_EQ(*again.camera_info, *messages.camera_info);
}

TEST(FrameConversions, FrameFromMessagesNamesTheImageThatDoesNotFit) {
  const CaptureFrame frame = cameraFrame();
  MeshStoreAccumulator store;
  FrameMessages m = frameMessages(frame, sampleHeader(), store);
  CaptureFrame back;
  m.depth = boost::make_shared<sensor_msgs::Image>(*m.depth);
  m.depth->width = 2;
  EXPECT_NE(frameFromMessages(m, back).find("depth: size is 2x2, expected 3x2"), std::string::npos);
  m = frameMessages(frame, sampleHeader(), store);
  m.color = boost::make_shared<sensor_msgs::Image>(*m.color);
  m.color->encoding = "bgr8";
  EXPECT_NE(frameFromMessages(m, back).find("color: encoding is 'bgr8'"), std::string::npos);
  m.color.reset();
  EXPECT_NE(frameFromMessages(m, back).find("needs its draws"), std::string::npos);
}

TEST(FrameConversions, WindowDepthFromMetresInvertsDepthMetres) {
  // Over the whole depth range of each draw's projection, including the far plane (no surface).
  CaptureFrame f = cameraFrame();
  const size_t n = 64;
  f.width = n, f.height = 1;
  f.draw_ids.resize(n);
  f.depth_window.resize(n);
  for (size_t i = 0; i < n; ++i) {
    f.draw_ids[i] = 1 + i % 2;
    f.depth_window[i] = i + 1 == n ? 1.0f : static_cast<float>(i + 1) / n;
  }
  const std::optional<FrameCamera> camera = chooseFrameCamera(f);
  ASSERT_TRUE(camera);
  const std::vector<float> metres = depthMetres(f, &*camera);
  size_t bad = 0;
  const std::vector<float> window = windowDepthFromMetres(f, metres, &camera->projection, &bad);
  EXPECT_EQ(bad, 1u);  // the last pixel: no surface, in a draw that has surfaces elsewhere
  for (size_t i = 0; i < n; ++i) EXPECT_NEAR(window[i], f.depth_window[i], 2e-6f) << "pixel " << i;
}

TEST(FrameConversions, CameraInfo) {
  PinholeIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = 500;
  k.fy = 510;
  k.cx = 319.5;
  k.cy = 239.5;
  const sensor_msgs::CameraInfo info = cameraInfo(&k, 640, 480, sampleHeader());
  EXPECT_EQ(info.width, 640u);
  EXPECT_EQ(info.height, 480u);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  EXPECT_EQ(info.D, std::vector<double>(5, 0.0));
  // K and P (row-major) hold the intrinsics, P with a zero last column (one camera); R is the identity.
  EXPECT_EQ(info.K, (decltype(info.K){500, 0, 319.5, 0, 510, 239.5, 0, 0, 1}));
  EXPECT_EQ(info.P, (decltype(info.P){500, 0, 319.5, 0, 0, 510, 239.5, 0, 0, 0, 1, 0}));
  EXPECT_EQ(info.R, (decltype(info.R){1, 0, 0, 0, 1, 0, 0, 0, 1}));

  const sensor_msgs::CameraInfo none = cameraInfo(nullptr, 640, 480, sampleHeader());
  EXPECT_EQ(none.K[0], 0);  // uncalibrated
  EXPECT_EQ(none.width, 640u);
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
