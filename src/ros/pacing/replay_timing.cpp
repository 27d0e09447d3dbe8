#include "viper/ros/pacing/replay_timing.h"

namespace viper {

namespace {
constexpr double kDefaultIntervalS = 0.1;
constexpr double kClampStepS = 1e-3;
}  // namespace

ReplayTiming::ReplayTiming(double rate, std::optional<double> start_time_s)
    : rate_(rate), start_time_s_(start_time_s) {}

double ReplayTiming::stampOf(double capture_time_s) {
  if (!started_) {
    if (start_time_s_) {
      offset_s_ = *start_time_s_ - capture_time_s;
    } else {
      offset_s_ = capture_time_s > 0.0 ? 0.0 : 1.0 - capture_time_s;
    }
  }
  if (!pass_first_time_s_) pass_first_time_s_ = capture_time_s;
  pass_last_time_s_ = capture_time_s;
  ++pass_frames_;

  double stamp = capture_time_s + offset_s_;
  clamped_ = started_ && stamp <= last_stamp_s_;
  if (clamped_) stamp = last_stamp_s_ + kClampStepS;
  if (!started_) first_stamp_s_ = stamp;
  started_ = true;
  last_stamp_s_ = stamp;
  return stamp;
}

void ReplayTiming::beginLoop() {
  if (!pass_first_time_s_) return;
  const double span = pass_last_time_s_ - *pass_first_time_s_;
  const double interval = pass_frames_ > 1 && span > 0.0 ? span / static_cast<double>(pass_frames_ - 1)
                                                          : kDefaultIntervalS;
  // The next pass's first frame (capture time pass_first) lands one interval after the last stamp.
  offset_s_ = last_stamp_s_ + interval - *pass_first_time_s_;
  pass_first_time_s_.reset();
  pass_frames_ = 0;
}

double ReplayTiming::dueAfterStart(double stamp_s) const {
  if (rate_ <= 0.0) return 0.0;
  return (stamp_s - first_stamp_s_) / rate_;
}

}  // namespace viper
