#include "frame_sink.h"

#include "finish_frame.h"

#include <unistd.h>

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

FrameSink::FrameSink(const std::string& path, const CaptureHeader& header, int zstd_level)
    : writer_(new CaptureWriter(path, header, zstd_level)), thread_([this] { run(); }) {}

FrameSink::~FrameSink() { close(); }

void FrameSink::push(CaptureFrame frame, RawImages raw) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return queue_.size() < 2 || closing_; });
  if (closing_) return;
  queue_.push_back(Item{std::move(frame), std::move(raw)});
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
    if (closing_ && !thread_.joinable()) return;
    closing_ = true;
    changed_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
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

void FrameSink::run() {
  for (;;) {
    Item item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;
      item = std::move(queue_.front());
      queue_.pop_front();
      changed_.notify_all();
    }
    const auto start = std::chrono::steady_clock::now();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!image_pool_.empty()) {
        CaptureFrame& images = image_pool_.back();
        item.frame.color_rgb.swap(images.color_rgb);
        item.frame.depth_window.swap(images.depth_window);
        item.frame.draw_ids.swap(images.draw_ids);
        item.frame.primitive_ids.swap(images.primitive_ids);
        image_pool_.pop_back();
      }
    }
    if (failed_) {
      ++dropped_after_failure_;
    } else {
      finishFrame(item.raw, item.frame);
      try {
        writer_->write(item.frame);
        busy_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      } catch (const std::exception& e) {
        failed_ = true;
        const std::string text = "writing frame " + std::to_string(item.frame.number) + " failed: " + e.what() +
                                 "; the capture stops there (the frames before it are intact), the program goes on";
        std::fprintf(stderr, "[viper capture] %s\n", text.c_str());
        tellLauncher(text);
      }
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (raw_pool_.size() < 4) raw_pool_.push_back(std::move(item.raw));
    if (image_pool_.size() < 2) {
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
