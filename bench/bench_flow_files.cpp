// Cost of writing and reading one 1920x1080 flow field as VIPER .npz (stored; deflate level 1,
// ISA-L's; levels 2 and 6, libdeflate's) and as Middlebury .flo, next to the float16 conversion
// alone, a memcpy of the same 16.6 MB of float32 flow and a plain write of those bytes to a file.
// The flow is synthetic, or the one in VIPER_BENCH_FLOW_NPZ (a flow .npz of generate's, say).
// Run: rosrun viper bench_flow_files
#include "viper/dataset/float16.h"
#include "viper/dataset/middlebury_flo.h"
#include "viper/dataset/viper_flow.h"

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

namespace {

using namespace viper::dataset;

constexpr uint32_t kW = 1920, kH = 1080;

// Flow of a camera driving forward: expansion from the focus of expansion below the horizon,
// growing with the inverse depth of a ground plane; no flow (NaN) in the sky above the horizon;
// a few boxes (cars) with their own motion.
const FlowImage& benchFlow() {
  static const FlowImage flow = [] {
    if (const char* npz = std::getenv("VIPER_BENCH_FLOW_NPZ")) return readViperFlow(npz);
    FlowImage f;
    f.width = kW;
    f.height = kH;
    f.uv.resize(2 * f.pixels());
    const float cx = kW / 2.0f, horizon = kH * 0.45f;
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        float u = std::nanf(""), v = std::nanf("");
        if (y > horizon) {
          const float inv_depth = (y - horizon) / (kH - horizon);
          u = (x - cx) * 0.02f * inv_depth;
          v = (y - horizon) * 0.02f * inv_depth;
        } else if (x % 640 < 200 && y > horizon * 0.5f) {  // buildings: static, far
          u = (x - cx) * 0.002f;
          v = (y - horizon) * 0.002f;
        }
        if ((x / 240) % 2 == 1 && y > horizon + 60 && y < horizon + 200) {  // cars
          u = 3.5f + 0.001f * x;
          v = -0.25f;
        }
        f.uv[2 * (y * kW + x)] = u;
        f.uv[2 * (y * kW + x) + 1] = v;
      }
    return f;
  }();
  return flow;
}

std::string benchPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("bench_flow_" + std::to_string(getpid()) + "_" + name)).string();
}

size_t fileSize(const std::string& path) { return std::filesystem::file_size(path); }

void BM_WriteViperFlow(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  ZipWriteOptions zip;
  zip.deflate_level = static_cast<int>(state.range(0));
  const std::string path = benchPath("w.npz");
  for (auto _ : state) writeViperFlow(path, flow, zip);
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
  state.counters["file_MB"] = fileSize(path) / 1e6;
  std::remove(path.c_str());
}
BENCHMARK(BM_WriteViperFlow)->Arg(0)->Arg(1)->Arg(2)->Arg(6)->Unit(benchmark::kMillisecond);

void BM_ReadViperFlow(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  ZipWriteOptions zip;
  zip.deflate_level = static_cast<int>(state.range(0));
  const std::string path = benchPath("r.npz");
  writeViperFlow(path, flow, zip);
  for (auto _ : state) benchmark::DoNotOptimize(readViperFlow(path));
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
  std::remove(path.c_str());
}
BENCHMARK(BM_ReadViperFlow)->Arg(0)->Arg(1)->Arg(6)->Unit(benchmark::kMillisecond);

void BM_WriteFlo(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  const std::string path = benchPath("w.flo");
  for (auto _ : state) writeMiddleburyFlo(path, flow);
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
  state.counters["file_MB"] = fileSize(path) / 1e6;
  std::remove(path.c_str());
}
BENCHMARK(BM_WriteFlo)->Unit(benchmark::kMillisecond);

void BM_ReadFlo(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  const std::string path = benchPath("r.flo");
  writeMiddleburyFlo(path, flow);
  for (auto _ : state) benchmark::DoNotOptimize(readMiddleburyFlo(path));
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
  std::remove(path.c_str());
}
BENCHMARK(BM_ReadFlo)->Unit(benchmark::kMillisecond);

void BM_FloatsToHalves(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  std::vector<uint16_t> out(flow.uv.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(floatsToHalves(flow.uv.data(), flow.uv.size(), out.data()));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
}
BENCHMARK(BM_FloatsToHalves)->Unit(benchmark::kMillisecond);

void BM_MemcpyFlow(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  std::vector<float> out(flow.uv.size());
  for (auto _ : state) {
    std::memcpy(out.data(), flow.uv.data(), flow.uv.size() * 4);
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
}
BENCHMARK(BM_MemcpyFlow)->Unit(benchmark::kMillisecond);

void BM_WriteRawFile(benchmark::State& state) {
  const FlowImage& flow = benchFlow();
  const std::string path = benchPath("raw");
  for (auto _ : state) {
    FILE* f = std::fopen(path.c_str(), "wb");
    std::fwrite(flow.uv.data(), 4, flow.uv.size(), f);
    std::fclose(f);
  }
  state.SetBytesProcessed(state.iterations() * flow.uv.size() * 4);
  std::remove(path.c_str());
}
BENCHMARK(BM_WriteRawFile)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
