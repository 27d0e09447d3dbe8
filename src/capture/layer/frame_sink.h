// Finishes captured frames (flip rows, decode ids, count visible pixels), encodes and writes them
// to the capture stream on background threads, so the program's render thread only pays for
// read-back. Several threads finish and compress frames side by side; each frame is appended in
// the order it was pushed, so the stream is the same whatever the number of threads.
#pragma once

#include "frame_target.h"
#include "viper/capture/capture_frame.h"
#include "viper/capture/capture_stream.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace viper {
namespace capture {

/// Background writers with a short bounded queue (the render thread waits when it is full, which
/// bounds memory and keeps the stream complete).
class FrameSink {
 public:
  /// Opens the stream, compressed by `header.codec` (at `zstd_level` for zstd; CaptureWriter's),
  /// and starts `threads` writer threads (at least 1). Throws std::runtime_error if the file
  /// cannot be opened.
  FrameSink(const std::string& path, const CaptureHeader& header, int zstd_level, int threads = 1);
  ~FrameSink();  ///< Drains the queue and closes the stream.

  void push(CaptureFrame frame, RawImages raw);
  /// Read-back buffers of an already written frame, to be filled again (their memory is kept:
  /// fresh 30 MB allocations per 1080p frame cost more in page faults than the copies).
  RawImages recycledRaw();
  /// Writes everything queued and closes the stream (idempotent).
  void close();
  /// Seconds the writer threads spent finishing, encoding and writing frames so far (summed).
  double busySeconds() const { return busy_s_; }
  int threads() const { return thread_count_; }

  /// Writer threads when VIPER_CAPTURE_WRITER_THREADS does not say: half the CPUs less one (the
  /// other half left to the program and its driver), from 1 to 8.
  static int defaultThreads();

 private:
  void run(CaptureChunkEncoder& encoder);

  struct Item {
    uint64_t sequence = 0;  ///< push order: the order of the stream
    CaptureFrame frame;
    RawImages raw;
  };
  std::string path_;
  std::unique_ptr<CaptureWriter> writer_;
  std::vector<std::unique_ptr<CaptureChunkEncoder>> encoders_;  // one per thread
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> queue_;
  std::vector<RawImages> raw_pool_;
  std::vector<CaptureFrame> image_pool_;  // frames holding only image vectors to reuse
  bool closing_ = false;
  uint64_t pushed_ = 0;  // sequence of the next push
  // Appending: the frame of sequence next_write_ is the next one into the file.
  std::mutex write_mutex_;
  std::condition_variable written_;
  uint64_t next_write_ = 0;
  // The first frame that could not be written (a full disk) stops the capture: a torn chunk ends
  // the stream there, the frames before it stay intact, and the program goes on.
  std::atomic<bool> failed_{false};
  uint64_t dropped_after_failure_ = 0;
  double busy_s_ = 0.0;
  size_t thread_count_ = 1;
  std::vector<std::thread> threads_;
};

}  // namespace capture
}  // namespace viper
