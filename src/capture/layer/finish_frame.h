// Turns the images read back at a swap into a capture frame's images. Pure (no GL calls); runs on
// the capture's writer thread, and in tests and benchmarks.
#pragma once

#include "frame_target.h"
#include "viper/capture/capture_frame.h"

namespace viper {
namespace capture {

/// Fills frame's color_rgb, depth_window, draw_ids and primitive_ids (top row first) from `raw`
/// (bottom row first, as glReadPixels gives it; depth and ids top row first where
/// raw.depth_ids_top_first), and every draw's visible_pixels. Ids that are not a
/// draw of the frame (0, NaN, larger than the number of draws) become draw 0, primitive 0. Missing
/// images give black color, far depth (1.0) and no draws. Reuses the frame's image memory.
void finishFrame(const RawImages& raw, CaptureFrame& frame);

/// The same, one pixel at a time: the reference that finishFrame's vectorised path is tested against.
void finishFrameScalar(const RawImages& raw, CaptureFrame& frame);

}  // namespace capture
}  // namespace viper
