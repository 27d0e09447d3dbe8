// Flow fields and flow images -> 32FC2 / mono8 messages -> back.
#include "viper/ros/conversions/flow_conversions.h"

#include "sample_header.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace viper {
namespace {

std_msgs::Header header() { return test::sampleHeader(); }

FlowField sampleField() {
  FlowField f;
  f.width = 3, f.height = 2;
  f.uv = {0.5f, -1.25f, NAN, NAN, 3.0f, 0.0f, -0.125f, 7.5f, 1e-3f, -1e-3f, 100.0f, -64.0f};
  f.visible = {255, 0, 255, 255, 0, 255};
  return f;
}

void expectSameFloats(const std::vector<float>& a, const std::vector<float>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::isnan(a[i])) EXPECT_TRUE(std::isnan(b[i])) << i;
    else EXPECT_EQ(a[i], b[i]) << i;
  }
}

TEST(FlowConversions, FlowFieldRoundTrip) {
  const FlowField field = sampleField();
  const FlowMessages m = toFlowMsgs(field, header());
  EXPECT_EQ(m.flow->encoding, "32FC2");
  EXPECT_EQ(m.flow->step, 24u);
  EXPECT_EQ(m.visible->encoding, "mono8");
  EXPECT_EQ(m.visible->header.stamp, header().stamp);
  FlowField back;
  ASSERT_EQ(flowFieldFromMsgs(*m.flow, *m.visible, back), "");
  EXPECT_EQ(back.width, 3u);
  EXPECT_EQ(back.height, 2u);
  expectSameFloats(back.uv, field.uv);
  EXPECT_EQ(back.visible, field.visible);
}

TEST(FlowConversions, FlowFieldChecks) {
  FlowField bad = sampleField();
  bad.visible.pop_back();
  EXPECT_THROW(toFlowMsgs(bad, header()), std::invalid_argument);
  const FlowMessages m = toFlowMsgs(sampleField(), header());
  sensor_msgs::Image small = *m.visible;
  small.height = 1;
  small.data.resize(3);
  FlowField out;
  EXPECT_NE(flowFieldFromMsgs(*m.flow, small, out).find("visible: size is 3x1, expected 3x2"), std::string::npos);
  EXPECT_NE(flowFieldFromMsgs(*m.visible, *m.visible, out).find("flow: encoding is 'mono8'"), std::string::npos);
  EXPECT_EQ(out.width, 0u);  // left as it was
}

TEST(FlowConversions, FlowImageRoundTripAnyStepEitherOrder) {
  dataset::FlowImage flow;
  flow.width = 3, flow.height = 2;
  flow.uv = sampleField().uv;
  const sensor_msgs::Image msg = toFlowMsg(flow, header());
  dataset::FlowImage back;
  ASSERT_EQ(flowFromMsg(msg, back), "");
  expectSameFloats(back.uv, flow.uv);

  // The same flow, big-endian with rows padded to 32 bytes.
  sensor_msgs::Image big = msg;
  big.is_bigendian = 1;
  big.step = 32;
  big.data.assign(64, 0);
  for (uint32_t y = 0; y < 2; ++y) {
    std::memcpy(big.data.data() + y * 32, msg.data.data() + y * 24, 24);
    for (size_t w = 0; w < 6; ++w) std::reverse(big.data.begin() + y * 32 + 4 * w, big.data.begin() + y * 32 + 4 * w + 4);
  }
  ASSERT_EQ(flowFromMsg(big, back), "");
  expectSameFloats(back.uv, flow.uv);
}

}  // namespace
}  // namespace viper
