// The amodal step at 1920x1080 on a synthetic frame (bench/synthetic_frames.h: 200 objects of 3
// box-shaped parts, one draw in 5 deformed), beside memcpy of the bytes it reads and writes: the
// instance id image (4 B/px) read, the cropped amodal masks (1 B a pixel of each box) written.
//   rosrun viper bench_amodal
#include "memcpy_floor.h"
#include "synthetic_frames.h"
#include "viper/ground_truth/amodal.h"
#include "viper/ground_truth/instance_pipeline.h"

#include <benchmark/benchmark.h>

#include <memory>

namespace viper {
namespace {

constexpr uint32_t kW = 1920, kH = 1080;
constexpr int kObjects = 200, kParts = 3, kDeformedEvery = 5;

struct AmodalInput {
  CaptureFrame frame;
  InstanceFrame instances;
  std::unique_ptr<InstancePipeline> pipeline;
  size_t mask_bytes = 0;
  AmodalInput() {
    LabelTable labels;
    frame = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, &labels, kDeformedEvery);
    pipeline = std::make_unique<InstancePipeline>(labels);
    std::vector<MeshRecord> meshes;
    for (const auto& d : frame.draws) meshes.push_back(bench::syntheticMesh(d.mesh_key));
    pipeline->addMeshes(meshes);
    pipeline->process(frame, instances);
    AmodalStep step;
    FrameAmodal out;
    StepProblems problems;
    step.process(frame, instances.objects, instances.instance_ids.data(), pipeline->meshes(), out, problems);
    for (const AmodalObject& a : out.objects) mask_bytes += a.mask.size();
  }
  size_t bytes() const { return size_t(kW) * kH * sizeof(int32_t) + mask_bytes; }
};

const AmodalInput& input() {
  static const AmodalInput in;
  return in;
}

void BM_MemcpyAmodalBytes(benchmark::State& state) { bench::copyBytes(state, input().bytes()); }

void BM_Amodal(benchmark::State& state) {
  const AmodalInput& in = input();
  AmodalStep step;
  FrameAmodal out;
  StepProblems problems;
  for (auto _ : state) {
    problems.clear();
    step.process(in.frame, in.instances.objects, in.instances.instance_ids.data(), in.pipeline->meshes(), out,
                 problems);
    benchmark::DoNotOptimize(out.objects.data());
  }
  uint64_t amodal = 0;
  for (const AmodalObject& a : out.objects) amodal += a.amodal_pixels;
  state.counters["objects"] = static_cast<double>(out.objects.size());
  state.counters["amodal_px"] = static_cast<double>(amodal);
  state.counters["problems"] = static_cast<double>(problems.size());
  state.SetBytesProcessed(state.iterations() * in.bytes());
}

BENCHMARK(BM_MemcpyAmodalBytes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Amodal)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace viper

BENCHMARK_MAIN();
