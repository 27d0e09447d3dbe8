// Cost of writing and reading one 1920x1080 capture frame (color 6 MB, depth 8 MB, draw and
// primitive ids 16 MB) next to a memcpy of the same bytes. Run: rosrun viper bench_capture_stream
#include "viper/capture/capture_stream.h"

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

namespace viper {
namespace {

constexpr uint32_t kW = 1920, kH = 1080;

uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  return x ^ (x >> 16);
}

// A rendered-looking frame: a smooth sky gradient, a perspective ground plane and ~300 draws as
// blocks of buildings and cars with flat-shaded faces, slight texture noise, and primitive ids
// that change every few pixels.
CaptureFrame makeBenchFrame() {
  CaptureFrame f;
  f.number = 1;
  f.time_s = 10.0;
  f.condition = "day";
  f.width = kW;
  f.height = kH;
  const size_t n = f.pixelCount();
  f.color_rgb.resize(3 * n);
  f.depth_window.resize(n);
  f.draw_ids.resize(n);
  f.primitive_ids.resize(n);
  constexpr uint32_t kBlockW = 96, kBlockH = 54, kHorizon = kH / 3;
  for (uint32_t y = 0; y < kH; ++y) {
    for (uint32_t x = 0; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      uint8_t* rgb = &f.color_rgb[3 * p];
      if (y < kHorizon) {  // sky: no draw, smooth gradient, far depth
        rgb[0] = uint8_t(90 + y * 80 / kHorizon);
        rgb[1] = uint8_t(140 + y * 60 / kHorizon);
        rgb[2] = 235;
        f.depth_window[p] = 1.0f;
        continue;
      }
      const uint32_t bx = x / kBlockW, by = (y - kHorizon) / kBlockH;
      const uint32_t draw = 1 + (by * (kW / kBlockW) + bx) % 300;
      const bool object = hash32(draw) % 3 != 0 && (x % kBlockW) > 8 && (y - kHorizon) % kBlockH > 6;
      const float ground = 0.95f + 0.05f * float(kH - y) / float(kH - kHorizon);
      f.draw_ids[p] = object ? draw : 301;  // 301: the ground plane
      f.primitive_ids[p] = object ? (x / 6 + (y / 5) * 17) % 2000 : (x / 40 + (y / 20) * 48);
      f.depth_window[p] = object ? ground - 0.002f - 0.00001f * float(x % kBlockW) : ground;
      const uint32_t shade = object ? 60 + hash32(draw) % 150 : 110 + (y - kHorizon) / 12;
      const uint32_t noise = hash32(uint32_t(p)) % 4;
      rgb[0] = uint8_t(shade + noise);
      rgb[1] = uint8_t(shade * 9 / 10 + noise);
      rgb[2] = uint8_t(shade * 8 / 10);
    }
  }
  for (uint32_t i = 0; i < 301; ++i) {
    DrawRecord d;
    d.index = i;
    d.mesh_key = 1000 + i % 40;
    d.vertex_buffer_key = 2000 + i % 40;
    d.index_buffer_key = 3000 + i % 40;
    d.program_key = 4000 + i % 5;
    d.texture_keys = {5000u + i % 17, 6000u + i % 3};
    d.matrix_flags = kHasWorld | kHasView | kHasProjection;
    d.world(0, 3) = float(i);
    d.primitive_count = 2000;
    if (i % 50 == 0) d.deformed_clip_xyzw.assign(4 * 3000, 0.25f * float(i));
    f.draws.push_back(d);
  }
  for (uint32_t m = 0; m < 10; ++m) {
    MeshRecord mesh;
    mesh.key = 1000 + m;
    mesh.positions_xyz.resize(3 * 3000);
    for (size_t k = 0; k < mesh.positions_xyz.size(); ++k) mesh.positions_xyz[k] = std::sin(float(k + m));
    mesh.indices.resize(3 * 2000);
    for (size_t k = 0; k < mesh.indices.size(); ++k) mesh.indices[k] = uint32_t(k * 7 % 3000);
    f.new_meshes.push_back(mesh);
  }
  return f;
}

const CaptureFrame& benchFrame() {
  static const CaptureFrame frame = makeBenchFrame();
  return frame;
}

size_t frameBytes() {
  static const size_t bytes = encodeFramePayload(benchFrame()).size();
  return bytes;
}

std::string tempPath(const char* tag) {
  return "/tmp/bench_capture_stream_" + std::string(tag) + "_" + std::to_string(::getpid()) + ".vcap";
}

void BM_Memcpy(benchmark::State& state) {
  std::string src(frameBytes(), '\1'), dst(frameBytes(), '\0');
  for (auto _ : state) {
    std::memcpy(&dst[0], src.data(), src.size());
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(int64_t(state.iterations() * src.size()));
}
BENCHMARK(BM_Memcpy)->Unit(benchmark::kMillisecond);

void BM_EncodePayload(benchmark::State& state) {
  std::string payload;
  for (auto _ : state) {
    encodeFramePayload(benchFrame(), payload);
    benchmark::DoNotOptimize(payload.data());
  }
  state.SetBytesProcessed(int64_t(state.iterations() * frameBytes()));
}
BENCHMARK(BM_EncodePayload)->Unit(benchmark::kMillisecond);

void BM_DecodePayload(benchmark::State& state) {
  const std::string payload = encodeFramePayload(benchFrame());
  CaptureFrame frame;
  for (auto _ : state) {
    decodeFramePayload(payload.data(), payload.size(), frame);
    benchmark::DoNotOptimize(frame.draw_ids.data());
  }
  state.SetBytesProcessed(int64_t(state.iterations() * frameBytes()));
}
BENCHMARK(BM_DecodePayload)->Unit(benchmark::kMillisecond);

// Args: the codec (1 zstd, 2 LZ4) and zstd's level.
void BM_EncodeAndWrite(benchmark::State& state) {
  const std::string path = tempPath("write");
  {
    CaptureHeader header;
    header.codec = static_cast<CaptureCodec>(state.range(0));
    CaptureWriter writer(path, header, int(state.range(1)));
    for (auto _ : state) writer.write(benchFrame());
    state.counters["compressed_MB_per_frame"] =
        double(writer.bytesWritten()) / double(state.iterations()) / 1e6;
  }
  std::remove(path.c_str());
  state.SetBytesProcessed(int64_t(state.iterations() * frameBytes()));
}
BENCHMARK(BM_EncodeAndWrite)
    ->Args({1, -5})
    ->Args({1, -1})
    ->Args({1, 1})
    ->Args({1, 3})
    ->Args({2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Storage for a frame's images that stays the same from frame to frame, as the bridge's recycled
// messages do (FrameImageMessages).
class ReusedStorage : public CaptureImageSink {
 public:
  void* imageStorage(CaptureImage image, const CaptureFrame&, size_t bytes) override {
    std::unique_ptr<char[]>& p = storage_[static_cast<int>(image)];
    size_t& size = size_[static_cast<int>(image)];
    if (size != bytes) p.reset(new char[bytes]), size = bytes;
    return p.get();
  }

 private:
  std::unique_ptr<char[]> storage_[4];
  size_t size_[4] = {0, 0, 0, 0};
};

// Arg: the codec (1 zstd, 2 LZ4); sink: the images decompressed straight into storage of the
// caller's (else into the frame's vectors).
void readFrames(benchmark::State& state, bool sink) {
  const std::string path = tempPath("read");
  {
    CaptureHeader header;
    header.codec = static_cast<CaptureCodec>(state.range(0));
    CaptureWriter writer(path, header, 1);
    for (int i = 0; i < 4; ++i) writer.write(benchFrame());
  }
  ReusedStorage storage;
  auto reader = std::make_unique<CaptureReader>(path);
  if (sink) reader->setImageSink(&storage);
  CaptureFrame frame;
  for (auto _ : state) {
    if (reader->next(frame) != CaptureReader::Status::kFrame) {
      state.PauseTiming();
      reader = std::make_unique<CaptureReader>(path);
      if (sink) reader->setImageSink(&storage);
      state.ResumeTiming();
      reader->next(frame);
    }
    benchmark::DoNotOptimize(frame.draws.data());
  }
  reader.reset();
  std::remove(path.c_str());
  state.SetBytesProcessed(int64_t(state.iterations() * frameBytes()));
}

void BM_ReadAndDecode(benchmark::State& state) { readFrames(state, false); }
BENCHMARK(BM_ReadAndDecode)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ReadIntoSink(benchmark::State& state) { readFrames(state, true); }
BENCHMARK(BM_ReadIntoSink)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace viper

BENCHMARK_MAIN();
