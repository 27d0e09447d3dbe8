// Replay stamps and pacing: positive, increasing, continued across loops.
#include "viper/ros/pacing/replay_timing.h"

#include <gtest/gtest.h>

namespace viper {
namespace {

TEST(ReplayTiming, PositiveCaptureTimesAreKept) {
  ReplayTiming t(1.0, std::nullopt);
  EXPECT_DOUBLE_EQ(t.stampOf(5.0), 5.0);
  EXPECT_DOUBLE_EQ(t.stampOf(5.1), 5.1);
}

TEST(ReplayTiming, ZeroCaptureTimeIsShiftedToPositive) {
  ReplayTiming t(1.0, std::nullopt);
  EXPECT_DOUBLE_EQ(t.stampOf(0.0), 1.0);
  EXPECT_DOUBLE_EQ(t.stampOf(0.5), 1.5);
}

TEST(ReplayTiming, StartTimeSetsFirstStamp) {
  ReplayTiming t(1.0, 1000.0);
  EXPECT_DOUBLE_EQ(t.stampOf(3.0), 1000.0);
  EXPECT_DOUBLE_EQ(t.stampOf(3.25), 1000.25);
}

TEST(ReplayTiming, LoopContinuesOneIntervalAfterLastFrame) {
  ReplayTiming t(1.0, std::nullopt);
  for (double time : {2.0, 2.1, 2.2, 2.3}) t.stampOf(time);
  t.beginLoop();
  EXPECT_NEAR(t.stampOf(2.0), 2.4, 1e-12);
  EXPECT_NEAR(t.stampOf(2.1), 2.5, 1e-12);
  EXPECT_FALSE(t.lastWasClamped());
  t.stampOf(2.2);
  t.stampOf(2.3);
  t.beginLoop();
  EXPECT_NEAR(t.stampOf(2.0), 2.8, 1e-12);
}

TEST(ReplayTiming, BackwardsTimeIsClamped) {
  ReplayTiming t(1.0, std::nullopt);
  t.stampOf(2.0);
  EXPECT_DOUBLE_EQ(t.stampOf(1.5), 2.001);
  EXPECT_TRUE(t.lastWasClamped());
  EXPECT_DOUBLE_EQ(t.stampOf(1.5), 2.002);  // equal time: still strictly increasing
}

TEST(ReplayTiming, DueTimesScaleWithRate) {
  ReplayTiming half(0.5, std::nullopt), fast(0.0, std::nullopt);
  half.stampOf(10.0);
  fast.stampOf(10.0);
  EXPECT_DOUBLE_EQ(half.dueAfterStart(half.stampOf(10.5)), 1.0);
  EXPECT_DOUBLE_EQ(fast.dueAfterStart(fast.stampOf(10.5)), 0.0);
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
