// Header stamps and pacing of a capture replay (ROS-free, times in seconds).
#pragma once

#include <cstdint>
#include <optional>

namespace viper {

/// Turns capture times into increasing header stamps and says when each frame is due.
///
/// stamp = capture time + offset. The offset is fixed by the first frame: `start_time_s - t0` when a
/// start time is given, else 0 if t0 > 0, else `1 - t0` (stamps must be positive: ROS time 0 means
/// "no time" under use_sim_time). Looping continues the stamps one mean frame interval after the
/// last frame of the previous pass, so stamps never repeat. A capture time that goes backwards
/// gets a stamp 1 ms after the previous one (and `lastWasClamped()` says so).
class ReplayTiming {
 public:
  /// `rate`: replay speed factor (1 = real time, 0 = as fast as possible).
  ReplayTiming(double rate, std::optional<double> start_time_s);

  /// Stamp for the next frame, captured at `capture_time_s`.
  double stampOf(double capture_time_s);
  /// Whether the last stampOf() had to clamp a capture time that went backwards.
  bool lastWasClamped() const { return clamped_; }
  /// Starts another pass over the same capture: its first frame follows the last stamp.
  void beginLoop();
  /// Wall seconds after the first frame's publication at which the frame stamped `stamp_s` is due;
  /// 0 when rate is 0 (as fast as possible).
  double dueAfterStart(double stamp_s) const;

 private:
  double rate_;
  std::optional<double> start_time_s_;
  bool started_ = false;
  bool clamped_ = false;
  double offset_s_ = 0.0;
  double first_stamp_s_ = 0.0;
  double last_stamp_s_ = 0.0;
  // Capture times of the current pass, for the loop interval.
  std::optional<double> pass_first_time_s_;
  double pass_last_time_s_ = 0.0;
  uint64_t pass_frames_ = 0;
};

}  // namespace viper
