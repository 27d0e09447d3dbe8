#include "frame_sink.h"

#include "finish_frame.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace viper {
namespace capture {
namespace {

// The capture launcher passes a pipe (VIPER_CAPTURE_STATUS_FD) and reports what arrives there once
// the program has exited, so a capture that failed is not taken for a complete one.
void tellLauncher(const std::string& text) {
  const char* fd = std::getenv("VIPER_CAPTURE_STATUS_FD");
  if (fd == nullptr || *fd == 0) return;
  const std::string line = text + "\n";
  const ssize_t written = ::write(std::atoi(fd), line.data(), line.size());
  (void)written;  // nobody to tell otherwise: the message is on stderr already
}

}  // namespace

int FrameSink::defaultThreads() {
  const int cpus = static_cast<int>(std::thread::hardware_concurrency());
  return std::max(1, std::min(8, cpus / 2 - 1));
}

FrameSink::FrameSink(const std::string& path, const CaptureHeader& header, int zstd_level, int threads)
    : path_(path), writer_(new CaptureWriter(path, header, zstd_level)) {
  thread_count_ = static_cast<size_t>(std::max(1, threads));
  for (size_t i = 0; i < thread_count_; ++i) encoders_.emplace_back(new CaptureChunkEncoder(header.codec, zstd_level));
  for (size_t i = 0; i < thread_count_; ++i) threads_.emplace_back([this, i] { run(*encoders_[i]); });
}

FrameSink::~FrameSink() { close(); }

void FrameSink::push(CaptureFrame frame, RawImages raw) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return queue_.size() < 2 || closing_; });
  if (closing_) return;
  queue_.push_back(Item{pushed_++, std::move(frame), std::move(raw)});
  changed_.notify_all();
}

RawImages FrameSink::recycledRaw() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (raw_pool_.empty()) return RawImages();
  RawImages r = std::move(raw_pool_.back());
  raw_pool_.pop_back();
  return r;
}

void FrameSink::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closing_ && threads_.empty()) return;
    closing_ = true;
    changed_.notify_all();
  }
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  if (failed_ && dropped_after_failure_ > 0)
    std::fprintf(stderr, "[viper capture] %llu later frames were not written\n",
                 static_cast<unsigned long long>(dropped_after_failure_));
  try {
    writer_->close();
  } catch (const std::exception& e) {
    if (!failed_) {  // after a failed frame, the end marker cannot be written either
      std::fprintf(stderr, "[viper capture] closing the stream failed: %s\n", e.what());
      tellLauncher(std::string("closing the capture stream failed: ") + e.what());
    }
  }
}

void FrameSink::run(CaptureChunkEncoder& encoder) {
  for (;;) {
    Item item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;
      item = std::move(queue_.front());
      queue_.pop_front();
      changed_.notify_all();
      if (!image_pool_.empty()) {
        CaptureFrame& images = image_pool_.back();
        item.frame.color_rgb.swap(images.color_rgb);
        item.frame.depth_window.swap(images.depth_window);
        item.frame.draw_ids.swap(images.draw_ids);
        item.frame.primitive_ids.swap(images.primitive_ids);
        image_pool_.pop_back();
      }
    }
    const auto start = std::chrono::steady_clock::now();
    std::string error;
    if (!failed_) {
      if (item.raw.prepare) item.raw.prepare(item.raw);
      finishFrame(item.raw, item.frame);
      try {
        encoder.encode(item.frame, path_);
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    item.raw.releaseViews();  // a read-back buffer of the GL's is free again
    item.raw.prepare = nullptr;
    // Busy time: the finish and the encoding here, the write below, not the wait for the turn.
    double busy = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    {
      // Appended in push order: wait for the frames before this one.
      std::unique_lock<std::mutex> lock(write_mutex_);
      written_.wait(lock, [&] { return next_write_ == item.sequence; });
      const auto write_start = std::chrono::steady_clock::now();
      if (failed_) {
        ++dropped_after_failure_;
      } else {
        try {
          if (!error.empty()) throw std::runtime_error(error);
          writer_->writeEncoded(encoder);
        } catch (const std::exception& e) {
          failed_ = true;
          const std::string text = "writing frame " + std::to_string(item.frame.number) + " failed: " + e.what() +
                                   "; the capture stops there (the frames before it are intact), the program goes on";
          std::fprintf(stderr, "[viper capture] %s\n", text.c_str());
          tellLauncher(text);
        }
      }
      busy += std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
      busy_s_ += busy;
      ++next_write_;
      written_.notify_all();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (raw_pool_.size() < thread_count_ + 3) raw_pool_.push_back(std::move(item.raw));
    if (image_pool_.size() < thread_count_ + 1) {
      CaptureFrame images;
      images.color_rgb.swap(item.frame.color_rgb);
      images.depth_window.swap(item.frame.depth_window);
      images.draw_ids.swap(item.frame.draw_ids);
      images.primitive_ids.swap(item.frame.primitive_ids);
      image_pool_.push_back(std::move(images));
    }
  }
}

}  // namespace capture
}  // namespace viper
