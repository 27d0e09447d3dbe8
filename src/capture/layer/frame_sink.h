// Finishes captured frames (flip rows, decode ids, count visible pixels) and writes them to the
// capture stream on a background thread, so the program's render thread only pays for read-back.
#pragma once

#include "frame_target.h"
#include "viper/capture/capture_frame.h"
#include "viper/capture/capture_stream.h"

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace viper {
namespace capture {

/// Background writer with a short bounded queue (the render thread waits when it is full, which
/// bounds memory and keeps the stream complete).
class FrameSink {
 public:
  /// Opens the stream, compressed by `header.codec` (at `zstd_level` for zstd; CaptureWriter's).
  /// Throws std::runtime_error if the file cannot be opened.
  FrameSink(const std::string& path, const CaptureHeader& header, int zstd_level);
  ~FrameSink();  ///< Drains the queue and closes the stream.

  void push(CaptureFrame frame, RawImages raw);
  /// Read-back buffers of an already written frame, to be filled again (their memory is kept:
  /// fresh 30 MB allocations per 1080p frame cost more in page faults than the copies).
  RawImages recycledRaw();
  /// Writes everything queued and closes the stream (idempotent).
  void close();
  /// Seconds the writer thread spent finishing and writing frames so far.
  double busySeconds() const { return busy_s_; }

 private:
  void run();

  struct Item {
    CaptureFrame frame;
    RawImages raw;
  };
  std::unique_ptr<CaptureWriter> writer_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> queue_;
  std::vector<RawImages> raw_pool_;
  std::vector<CaptureFrame> image_pool_;  // frames holding only image vectors to reuse
  bool closing_ = false;
  // The first frame that could not be written (a full disk) stops the capture: a torn chunk ends
  // the stream there, the frames before it stay intact, and the program goes on.
  bool failed_ = false;
  uint64_t dropped_after_failure_ = 0;
  double busy_s_ = 0.0;
  std::thread thread_;
};

}  // namespace capture
}  // namespace viper
