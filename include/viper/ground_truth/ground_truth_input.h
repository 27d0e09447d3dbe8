// One frame as the ground-truth steps read it (docs/design.md, "Ground truth on core types"): its
// draws and size, its stamp, and its pixels wherever they are stored (the messages it came in, say).
// A node decodes its messages into it; `generate` decodes each raw frame into it once, and every step
// reads that one.
#pragma once

#include "viper/capture/capture_frame.h"

#include <cstdint>
#include <memory>

namespace viper {

/// A frame's stamp (a ROS header stamp: seconds and nanoseconds, nanoseconds below 1e9). Frames
/// must come in stamp order; the steps' velocities use seconds().
struct FrameStamp {
  uint32_t sec = 0, nsec = 0;
  /// The stamp in seconds, as ros::Time::toSec() gives it (the same double, bit for bit).
  double seconds() const { return static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec); }
  bool isZero() const { return sec == 0 && nsec == 0; }
  bool operator==(const FrameStamp& o) const { return sec == o.sec && nsec == o.nsec; }
  bool operator!=(const FrameStamp& o) const { return !(*this == o); }
  bool operator<(const FrameStamp& o) const { return sec < o.sec || (sec == o.sec && nsec < o.nsec); }
  bool operator<=(const FrameStamp& o) const { return !(o < *this); }
};

/// One frame's inputs. `frame` holds the number, time (the stamp's seconds), size, condition and
/// draws; its image vectors may be empty, the pixels being at the pointers (width*height values
/// each, null where the image is missing or unusable: a step that needs it then drops the frame).
/// `owner` keeps the pixels alive as long as a step holds the frame (the flow step's window).
struct GroundTruthInput {
  CaptureFrame frame;
  FrameStamp stamp;
  const uint32_t* draw_ids = nullptr;       ///< draw index + 1, 0 = none
  const float* depth_m = nullptr;           ///< metres along the optical axis, NaN = no surface
  const uint32_t* primitive_ids = nullptr;  ///< triangle index within the draw
  const uint8_t* color_rgb = nullptr;       ///< rgb8, 3 bytes a pixel (the labelled cloud's colours)
  std::shared_ptr<const void> owner;
};
using GroundTruthInputPtr = std::shared_ptr<const GroundTruthInput>;

}  // namespace viper
