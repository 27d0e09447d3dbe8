// The evaluate node's own input checks and conversions (no roscore); images and poses:
// test/ros/conversions.
#include "viper/ros/evaluation/evaluate_inputs.h"

#include <gtest/gtest.h>

namespace viper {
namespace {

sensor_msgs::Image image(const std::string& encoding, uint32_t w, uint32_t h, size_t bpp) {
  sensor_msgs::Image m;
  m.encoding = encoding, m.width = w, m.height = h, m.step = w * bpp;
  m.data.assign(static_cast<size_t>(m.step) * h, 0);
  return m;
}

TEST(EvaluateInputs, InstancePredictions) {
  InstancePredictionArray msg;
  msg.instances.resize(2);
  msg.instances[0].class_id = 24, msg.instances[0].score = 0.5f;
  msg.instances[0].mask = image("mono8", 4, 3, 1);  // the whole frame
  msg.instances[0].mask.data[5] = 255;
  msg.instances[1].class_id = 26, msg.instances[1].score = 0.25f;
  msg.instances[1].x_offset = 2, msg.instances[1].y_offset = 1;
  msg.instances[1].mask = image("mono8", 2, 2, 1);  // the bottom right corner
  std::vector<BoxedInstance> out;
  ASSERT_EQ(toBoxedInstances(msg, 4, 3, out), "");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].class_id, 24);
  EXPECT_DOUBLE_EQ(out[0].score, 0.5);
  EXPECT_EQ(out[0].width, 4u);
  EXPECT_EQ(out[0].height, 3u);
  EXPECT_EQ(out[0].mask, msg.instances[0].mask.data.data()) << "no copy";
  EXPECT_EQ(out[0].mask[5], 255);
  EXPECT_EQ(out[1].class_id, 26);
  EXPECT_EQ(out[1].x0, 2u);
  EXPECT_EQ(out[1].y0, 1u);
  EXPECT_EQ(out[1].width, 2u);

  msg.instances[1].x_offset = 3;
  EXPECT_EQ(toBoxedInstances(msg, 4, 3, out), "instance 1 mask 2x2 at (3, 1) leaves the 4x3 frame");
  EXPECT_TRUE(out.empty());
  msg.instances[1].x_offset = 2;
  msg.instances[1].mask = image("rgb8", 2, 2, 3);
  EXPECT_EQ(toBoxedInstances(msg, 4, 3, out), "instance 1 mask: encoding is 'rgb8', expected mono8 (2x2)");
  msg.instances[1].mask = image("mono8", 2, 2, 1);
  msg.instances[1].score = NAN;
  EXPECT_EQ(toBoxedInstances(msg, 4, 3, out), "instance 1 has a non-finite score");
}

TEST(EvaluateInputs, SparseFlowConventions) {
  opencv_apps::FlowArrayStamped msg;
  msg.flow.resize(1);
  msg.flow[0].point.x = 10, msg.flow[0].point.y = 20;
  msg.flow[0].velocity.x = 1.5, msg.flow[0].velocity.y = -2;
  // fback_flow: the point is in the first frame.
  auto first = fromFlowArray(msg, SparsePoints::kFirstFrame);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_DOUBLE_EQ(first[0].x, 10);
  EXPECT_DOUBLE_EQ(first[0].y, 20);
  EXPECT_DOUBLE_EQ(first[0].u, 1.5);
  EXPECT_DOUBLE_EQ(first[0].v, -2);
  // lk_flow: the point is where the feature went; it started at point - velocity.
  auto second = fromFlowArray(msg, SparsePoints::kSecondFrame);
  EXPECT_DOUBLE_EQ(second[0].x, 8.5);
  EXPECT_DOUBLE_EQ(second[0].y, 22);
  EXPECT_DOUBLE_EQ(second[0].u, 1.5);
}

}  // namespace
}  // namespace viper
