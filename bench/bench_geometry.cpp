// Normals and labelled clouds of a 1920x1080 frame beside memcpy of the bytes each kernel reads and
// writes (bench/memcpy_floor.h). Figures: docs/figures.md.
#include "memcpy_floor.h"
#include "synthetic_frames.h"

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/labelled_cloud.h"
#include "viper/ground_truth/normals.h"

#include <benchmark/benchmark.h>

#include <vector>

namespace viper {
namespace {

using bench::copyBytes;

constexpr uint32_t kW = 1920, kH = 1080;

// Normals read draw ids, primitive ids and depth (4 + 4 + 4) and write three floats (12).
constexpr size_t kNormalBytesPerPixel = 4 + 4 + 4 + 12;
// The cloud reads depth, rgb, class and instance (4 + 3 + 1 + 4) and writes a 24-byte point.
constexpr size_t kCloudBytesPerPixel = 4 + 3 + 1 + 4 + 24;

void BM_MemcpyNormalBytes(benchmark::State& state) { copyBytes(state, size_t(kW) * kH * kNormalBytesPerPixel); }

// 60 objects of 3 parts, one draw in 4 deformed: a triangle changes every 8 to 16 pixels along a
// row (the synthetic frame's tiles), more often than in a rendered scene.
void BM_Normals(benchmark::State& state) {
  const CaptureFrame f = bench::syntheticFrame(kW, kH, 60, 3, 0, nullptr, 4);
  MeshRegistry meshes;
  for (const DrawRecord& d : f.draws)
    if (!meshes.find(d.mesh_key)) meshes.add(bench::syntheticMesh(d.mesh_key));
  // Depth only decides where there is a surface: everywhere here.
  const std::vector<float> depth(f.pixelCount(), 20.0f);
  const GroundTruthInput in{f, FrameStamp(), f.draw_ids.data(), depth.data(), f.primitive_ids.data(), nullptr};
  const FrameCamera camera{f.draws[0].view, f.draws[0].projection, 0};
  std::vector<float> out(3 * f.pixelCount());
  NormalStats stats;
  for (auto _ : state) {
    computeNormals(in, camera, meshes, out.data(), &stats);
    benchmark::DoNotOptimize(out.data());
  }
  if (stats.with_normal != f.pixelCount()) state.SkipWithError("not every pixel has a normal");
  state.SetBytesProcessed(state.iterations() * f.pixelCount() * kNormalBytesPerPixel);
}

void BM_MemcpyCloudBytes(benchmark::State& state) {
  const size_t k = size_t(state.range(0));
  const size_t points = ((kW + k - 1) / k) * ((kH + k - 1) / k);
  copyBytes(state, points * kCloudBytesPerPixel);
}

// Every k-th pixel (state.range(0)) of a frame with depth everywhere.
void BM_LabelledCloud(benchmark::State& state) {
  const CaptureFrame f = bench::syntheticFrame(kW, kH, 60, 3, 0, nullptr);
  const std::optional<FrameCamera> camera = chooseFrameCamera(f);
  const std::vector<float> depth = depthMetres(f, &*camera);
  std::vector<uint8_t> classes(f.pixelCount());
  std::vector<int32_t> instances(f.pixelCount());
  for (size_t p = 0; p < f.pixelCount(); ++p) classes[p] = uint8_t(f.draw_ids[p] % 32), instances[p] = int32_t(f.draw_ids[p]);
  CloudImages images{kW, kH, depth.data(), f.color_rgb.data(), classes.data(), instances.data()};
  const PinholeIntrinsics k = intrinsicsFromGlProjection(camera->projection, kW, kH);
  const int decimation = int(state.range(0));
  std::vector<CloudPoint> cloud(cloudSize(kW, kH, decimation).points());
  size_t with_depth = 0;
  for (auto _ : state) {
    with_depth = labelledCloud(images, k, decimation, cloud.data());
    benchmark::DoNotOptimize(cloud.data());
  }
  if (with_depth != cloud.size()) state.SkipWithError("not every point has depth");
  state.SetBytesProcessed(state.iterations() * cloud.size() * kCloudBytesPerPixel);
}

}  // namespace

BENCHMARK(BM_MemcpyNormalBytes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Normals)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MemcpyCloudBytes)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LabelledCloud)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace viper

BENCHMARK_MAIN();
