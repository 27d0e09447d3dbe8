#include "frame_sink.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace viper {
namespace capture {

void finishFrame(const RawImages& raw, CaptureFrame& frame) {
  const size_t w = static_cast<size_t>(raw.width), h = static_cast<size_t>(raw.height);
  frame.width = static_cast<uint32_t>(w);
  frame.height = static_cast<uint32_t>(h);
  const size_t n = w * h;
  // Every element is written below; resize keeps recycled memory without refilling it.
  frame.color_rgb.resize(n * 3);
  frame.depth_window.resize(n);
  frame.draw_ids.resize(n);
  frame.primitive_ids.resize(n);
  std::vector<uint32_t> visible(frame.draws.size() + 1, 0);
  const bool has_color = raw.rgba.size() >= n * 4, has_ids = raw.ids.size() >= n * 2;
  const bool depth_float = raw.depth.size() >= n, depth_packed = raw.depth_24_8.size() >= n;
  const float max_id = static_cast<float>(frame.draws.size());
  for (size_t y = 0; y < h; ++y) {
    const size_t src_row = (h - 1 - y) * w, dst_row = y * w;  // GL rows are bottom-up
    if (!has_color) std::memset(&frame.color_rgb[dst_row * 3], 0, w * 3);
    if (!depth_float && !depth_packed) std::fill_n(&frame.depth_window[dst_row], w, 1.0f);
    if (has_color) {
      const uint8_t* s = &raw.rgba[src_row * 4];
      uint8_t* d = &frame.color_rgb[dst_row * 3];
      for (size_t x = 0; x < w; ++x, s += 4, d += 3) d[0] = s[0], d[1] = s[1], d[2] = s[2];
    }
    if (depth_float) std::memcpy(&frame.depth_window[dst_row], &raw.depth[src_row], w * sizeof(float));
    if (depth_packed) {
      const uint32_t* s = &raw.depth_24_8[src_row];
      float* d = &frame.depth_window[dst_row];
      for (size_t x = 0; x < w; ++x) d[x] = static_cast<float>(s[x] >> 8) * (1.0f / 16777215.0f);
    }
    uint32_t* draw_ids = &frame.draw_ids[dst_row];
    uint32_t* primitive_ids = &frame.primitive_ids[dst_row];
    if (!has_ids) {
      std::fill_n(draw_ids, w, 0u);
      std::fill_n(primitive_ids, w, 0u);
      continue;
    }
    const float* ids = &raw.ids[src_row * 2];
    for (size_t x = 0; x < w; ++x) {
      const float id = ids[2 * x];
      if (!(id >= 1.0f) || id > max_id) {  // also rejects NaN
        draw_ids[x] = primitive_ids[x] = 0;
        continue;
      }
      const uint32_t draw_id = static_cast<uint32_t>(id + 0.5f);
      draw_ids[x] = draw_id;
      primitive_ids[x] = static_cast<uint32_t>(std::max(0.0f, ids[2 * x + 1]) + 0.5f);
      ++visible[draw_id];
    }
  }
  for (size_t i = 0; i < frame.draws.size(); ++i) frame.draws[i].visible_pixels = visible[i + 1];
}

FrameSink::FrameSink(const std::string& path, const CaptureHeader& header)
    : writer_(new CaptureWriter(path, header, 1)), thread_([this] { run(); }) {}

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
  try {
    writer_->close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[viper capture] closing the stream failed: %s\n", e.what());
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
    finishFrame(item.raw, item.frame);
    try {
      writer_->write(item.frame);
      busy_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "[viper capture] writing frame %llu failed: %s\n",
                   static_cast<unsigned long long>(item.frame.number), e.what());
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
