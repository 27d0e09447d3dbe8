// What `capture` tells a capture layer through the environment (VIPER_CAPTURE_*), read the same way
// by the OpenGL interceptor and the Vulkan layer.
#pragma once

#include "viper/capture/capture_stream.h"

#include <cstdint>
#include <string>

namespace viper {
namespace capture {

struct CaptureSettings {
  std::string output;  ///< empty: no destination, the layer only passes calls on
  std::string condition;
  std::string profile_path;  ///< empty: the default profile
  uint64_t frame_limit = 0;  ///< 0: no limit
  uint64_t skip_frames = 0;
  double fixed_fps = 0.0;  ///< > 0: frame n is stamped n / fixed_fps
  bool start_on_scene = false;
  CaptureHeader header;  ///< program and codec (the profile is the layer's to fill in)
  int zstd_level = 1;
  int writer_threads = 1;
  std::string readback = "auto";
};

/// Reads VIPER_CAPTURE_*. Throws std::runtime_error naming the variable when a value is bad
/// (`capture` checks them first; a layer preloaded by hand reports them).
CaptureSettings readCaptureSettings();

/// CLOCK_MONOTONIC in seconds: frame stamps of programs without a fixed rate.
double monotonicSeconds();

}  // namespace capture
}  // namespace viper
