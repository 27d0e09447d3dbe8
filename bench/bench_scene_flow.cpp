// Per-frame cost of the scene flow (scene_flow.h) at 1920x1080 with ~200 objects, on one core,
// next to memcpy of the bytes it touches; and the forward flow alone beside the forward flow with
// its scene flow, as the flow step computes them (the scene flow is a pass after the flow, taken
// only while asked for).
// Run: rosrun viper bench_scene_flow
#include "memcpy_floor.h"
#include "synthetic_frames.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/flow.h"
#include "viper/ground_truth/scene_flow.h"

#include <benchmark/benchmark.h>

#include <vector>

namespace viper {
namespace {

constexpr uint32_t kW = 1920, kH = 1080;
constexpr int kObjects = 200, kParts = 3;

// Reads draw id, metres, primitive id (4+4+4) and the flow (8, for its mask), writes 4 floats (16).
constexpr size_t kSceneFlowBytesPerPixel = 4 + 4 + 4 + 8 + 16;
void BM_MemcpySceneFlowBytes(benchmark::State& state) {
  bench::copyBytes(state, size_t(kW) * kH * kSceneFlowBytesPerPixel);
}

// Two synthetic frames read as the flow step reads them (metres), the forward flow a -> b.
struct Pair {
  CaptureFrame a = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, nullptr);
  CaptureFrame b = bench::syntheticFrame(kW, kH, kObjects, kParts, 1, nullptr);
  std::vector<float> metres_a = depthMetres(a, nullptr), metres_b = depthMetres(b, nullptr);
  std::vector<int32_t> a_to_b;
  FlowFramePixels pa, pb;
  std::vector<float> uv = std::vector<float>(2 * a.pixelCount());
  std::vector<uint8_t> visible = std::vector<uint8_t>(a.pixelCount());
  std::vector<float> scene = std::vector<float>(kSceneFlowChannels * a.pixelCount());
  MeshRegistry meshes;
  Eigen::Isometry3d a_from_b = opticalMotion(a.draws.front().view, b.draws.front().view);

  Pair() {
    std::vector<int32_t> ids(a.draws.size());
    for (size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<int32_t>(k / kParts + 1);
    a_to_b = associateDraws(a, ids, b, ids);
    pa = flowFramePixels(a), pb = flowFramePixels(b);
    pa.depth_window = pb.depth_window = nullptr;
    pa.depth_metres = metres_a.data(), pb.depth_metres = metres_b.data();
  }
  void flow() { computeFlow(pa, pb, a_to_b, metres_b.data(), meshes, uv.data(), visible.data()); }
  void sceneFlow(SceneFlowStats* stats = nullptr) {
    computeSceneFlow(pa, pb, a_to_b, meshes, a_from_b, uv.data(), scene.data(), stats);
  }
};

// The scene flow alone, from a flow computed once.
void BM_SceneFlow(benchmark::State& state) {
  Pair p;
  p.flow();
  SceneFlowStats stats;
  for (auto _ : state) {
    p.sceneFlow(&stats);
    benchmark::DoNotOptimize(p.scene.data());
  }
  state.counters["defined_px"] = static_cast<double>(stats.defined);
  state.SetBytesProcessed(state.iterations() * size_t(kW) * kH * kSceneFlowBytesPerPixel);
}

// The forward flow (argument 0), and the forward flow with its scene flow (1).
void BM_ForwardFlowWithSceneFlow(benchmark::State& state) {
  const bool scene = state.range(0) == 1;
  state.SetLabel(scene ? "flow + scene flow" : "flow alone");
  Pair p;
  for (auto _ : state) {
    p.flow();
    if (scene) p.sceneFlow();
    benchmark::DoNotOptimize(p.uv.data());
    benchmark::DoNotOptimize(p.scene.data());
  }
}

}  // namespace

BENCHMARK(BM_MemcpySceneFlowBytes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SceneFlow)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ForwardFlowWithSceneFlow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace viper

BENCHMARK_MAIN();
