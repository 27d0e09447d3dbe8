// The capture writer thread's per-frame pixel work at 1920x1080 (finishFrame: flip rows, RGBA to
// RGB, decode draw and primitive ids, count visible pixels per draw), vectorised and one pixel at a
// time, next to memcpy of the bytes it reads and writes.
// Run: rosrun viper bench_capture_finish
#include "finish_frame.h"

#include <benchmark/benchmark.h>

#include <cstring>
#include <random>

namespace viper {
namespace capture {
namespace {

constexpr int kW = 1920, kH = 1080;
constexpr uint32_t kDraws = 300;
// Reads RGBA (4), depth (4), ids (8); writes RGB (3), depth (4), draw and primitive ids (4 + 4).
constexpr size_t kBytesPerPixel = 4 + 4 + 8 + 3 + 4 + 4 + 4;

// Read-back images whose draws run ~100 pixels along a row, as the world's do at 1080p, with sky
// (id 0) in the top quarter.
RawImages worldLikeImages() {
  std::mt19937 rng(1);
  RawImages raw;
  raw.width = kW;
  raw.height = kH;
  const size_t n = static_cast<size_t>(kW) * kH;
  raw.rgba.resize(4 * n);
  for (auto& b : raw.rgba) b = static_cast<uint8_t>(rng());
  raw.depth.assign(n, 0.97f);
  raw.ids.resize(2 * n);
  for (int y = 0; y < kH; ++y) {
    float id = 0.0f;
    for (int x = 0; x < kW; ++x) {
      const size_t i = static_cast<size_t>(kH - 1 - y) * kW + x;  // bottom row first
      if (rng() % 100 == 0) id = y < kH / 4 ? 0.0f : static_cast<float>(1 + rng() % kDraws);
      raw.ids[2 * i] = id;
      raw.ids[2 * i + 1] = static_cast<float>(rng() % 4000);
    }
  }
  return raw;
}

void BM_MemcpyFinishBytes(benchmark::State& state) {
  const size_t bytes = size_t(kW) * kH * kBytesPerPixel / 2;  // half read, half written
  std::vector<char> src(bytes, 1), dst(bytes);
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), bytes);
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * bytes * 2);
}

template <void (*Finish)(const RawImages&, CaptureFrame&)>
void BM_Finish(benchmark::State& state) {
  const RawImages raw = worldLikeImages();
  CaptureFrame frame;
  frame.draws.resize(kDraws);
  for (auto _ : state) {
    Finish(raw, frame);  // the writer thread reuses the frame's image memory the same way
    benchmark::DoNotOptimize(frame.draw_ids.data());
  }
  state.SetBytesProcessed(state.iterations() * size_t(kW) * kH * kBytesPerPixel);
}

void BM_FinishFrame(benchmark::State& state) { BM_Finish<finishFrame>(state); }
void BM_FinishFrameScalar(benchmark::State& state) { BM_Finish<finishFrameScalar>(state); }

BENCHMARK(BM_MemcpyFinishBytes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FinishFrame)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FinishFrameScalar)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace capture
}  // namespace viper

BENCHMARK_MAIN();
