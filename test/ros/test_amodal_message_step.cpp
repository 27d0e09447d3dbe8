// The amodal node's work on messages with bad input (no roscore): an instance image that is not
// 32SC1 or whose bytes do not match its size drops the frame with a problem naming that input; an
// object naming a draw the frame lacks, or a draw whose mesh never arrived, is named and left out,
// the frame kept; a drawable object comes out with its mask.
#include "viper/ros/ground_truth/amodal_node.h"

#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include <cstring>

namespace viper {
namespace {

sensor_msgs::Image instanceImage(uint32_t w, uint32_t h, int32_t id) {
  sensor_msgs::Image m;
  m.width = w, m.height = h, m.step = 4 * w;
  m.encoding = sensor_msgs::image_encodings::TYPE_32SC1;
  m.data.resize(size_t(m.step) * h);
  for (size_t p = 0; p < size_t(w) * h; ++p) std::memcpy(m.data.data() + 4 * p, &id, 4);
  return m;
}

ObjectArray oneObject(int32_t track, uint32_t draw) {
  ObjectArray objects;
  objects.objects.resize(1);
  objects.objects[0].track_id = track;
  objects.objects[0].class_id = 24;
  objects.objects[0].draws = {draw};
  objects.objects[0].world_pose.orientation.w = 1;
  return objects;
}

TEST(AmodalMessageStep, BadInstanceImageDropsTheFrame) {
  AmodalMessageStep step;
  DrawList draws;
  draws.frame_number = 7;
  FrameAmodal amodal;
  sensor_msgs::Image ids = instanceImage(8, 6, 0);
  ids.encoding = sensor_msgs::image_encodings::MONO8;
  StepProblems problems;
  EXPECT_FALSE(step.process(draws, ids, oneObject(1, 0), amodal, problems));
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].input, StepInput::kDrawIds);  // the node names it with its instance_ids topic
  EXPECT_EQ(problems[0].severity, StepSeverity::kError);
  EXPECT_NE(problems[0].text.find("frame 7"), std::string::npos) << problems[0].text;
  EXPECT_NE(problems[0].text.find("mono8"), std::string::npos) << problems[0].text;

  ids = instanceImage(8, 6, 0);
  ids.data.resize(ids.data.size() - 4);  // a pixel short
  problems.clear();
  EXPECT_FALSE(step.process(draws, ids, oneObject(1, 0), amodal, problems));
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].input, StepInput::kDrawIds);
}

TEST(AmodalMessageStep, UndrawableObjectsAreNamedAndLeftOut) {
  AmodalMessageStep step;
  DrawList draws;
  draws.frame_number = 3;
  draws.draws.resize(1);
  draws.draws[0].mesh_key = 42;  // never arrives
  draws.draws[0].matrix_flags = Draw::HAS_WORLD | Draw::HAS_VIEW | Draw::HAS_PROJECTION;
  const sensor_msgs::Image ids = instanceImage(8, 6, 5);
  FrameAmodal amodal;
  for (uint32_t draw : {0u, 9u}) {
    StepProblems problems;
    ASSERT_TRUE(step.process(draws, ids, oneObject(5, draw), amodal, problems)) << "draw " << draw;
    EXPECT_TRUE(amodal.objects.empty()) << "draw " << draw;
    ASSERT_FALSE(problems.empty()) << "draw " << draw;
    EXPECT_EQ(problems[0].input, StepInput::kObjects);
    EXPECT_NE(problems[0].text.find("track 5"), std::string::npos) << problems[0].text;
    EXPECT_NE(problems[0].text.find(draw == 0 ? "never arrived" : "names draw 9"), std::string::npos)
        << problems[0].text;
    EXPECT_EQ(amodal.width, 8u);
    EXPECT_EQ(amodal.height, 6u);
  }
}

}  // namespace
}  // namespace viper
