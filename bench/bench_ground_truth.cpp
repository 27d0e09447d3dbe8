// Per-frame cost of the ground-truth kernels at 1920x1080 with ~200 objects, on one core, next to
// memcpy of the bytes each kernel touches (of the class pictures and depth conversions: of their
// output): synthetic frames, and (with VIPER_BENCH_CAPTURE and VIPER_BENCH_LABELS set, see
// scripts/measure_figures.sh) a real world capture.
// Run: rosrun viper bench_ground_truth
#include "memcpy_floor.h"
#include "synthetic_frames.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/flow.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/semantic_overlay.h"

#include <benchmark/benchmark.h>

#ifdef __x86_64__
#include <immintrin.h>
#endif

#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>

namespace viper {
namespace {

constexpr uint32_t kW = 1920, kH = 1080;
constexpr int kObjects = 200, kParts = 3;

using bench::copyBytes;

// instances: reads draw ids (4 B/px), writes semantic (1), instance ids (4), boundaries (1) and
// reads the instance ids back for boundaries (4 x 4-neighbours, mostly cached).
constexpr size_t kInstanceBytesPerPixel = 4 + 1 + 4 + 1;

void BM_MemcpyInstanceBytes(benchmark::State& state) { copyBytes(state, size_t(kW) * kH * kInstanceBytesPerPixel); }

void BM_InstancesAndTracking(benchmark::State& state) {
  LabelTable labels;
  std::vector<CaptureFrame> frames;
  for (int s = 0; s < 8; ++s) frames.push_back(bench::syntheticFrame(kW, kH, kObjects, kParts, s, &labels));
  InstancePipeline pipeline(labels);
  std::vector<MeshRecord> meshes;
  for (const auto& d : frames[0].draws) meshes.push_back(bench::syntheticMesh(d.mesh_key));
  pipeline.addMeshes(meshes);
  size_t i = 0, objects = 0;
  InstanceFrame out;
  for (auto _ : state) {
    CaptureFrame& f = frames[i % frames.size()];
    f.time_s = static_cast<double>(i) / 15.0;  // time keeps increasing across the loop
    pipeline.process(f, out);
    objects = out.objects.size();
    benchmark::DoNotOptimize(out.semantic.data());
    ++i;
  }
  state.counters["objects"] = static_cast<double>(objects);
  state.SetBytesProcessed(state.iterations() * size_t(kW) * kH * kInstanceBytesPerPixel);
}

// flow, each direction: reads draw id, depth, primitive id (4+4+4), the other frame's depth at the
// target (4), writes (u, v) and the mask (8+1).
constexpr size_t kFlowBytesPerPixel = 4 + 4 + 4 + 4 + 8 + 1;

void BM_MemcpyFlowBytes(benchmark::State& state) { copyBytes(state, 2 * size_t(kW) * kH * kFlowBytesPerPixel); }

#ifdef __x86_64__
// One direction's streams of the flow kernel with none of its arithmetic: a's draw ids and depth and
// b's depth at the same pixel read, (u, v) written with the kernel's non-temporal stores (uv
// 16-byte aligned) and the mask with plain ones; AVX2, 8 pixels a step.
__attribute__((target("avx2"))) void flowStreams(const uint32_t* ids, const float* depth_a, const float* depth_b,
                                                 size_t n, float* uv, uint8_t* visible) {
  for (size_t x = 0; x + 8 <= n; x += 8) {
    const __m256 id = _mm256_cvtepi32_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + x)));
    const __m256 d = _mm256_loadu_ps(depth_a + x), there = _mm256_loadu_ps(depth_b + x);
    const __m256 u = _mm256_add_ps(d, id);
    const __m256 lo = _mm256_unpacklo_ps(u, there), hi = _mm256_unpackhi_ps(u, there);
    _mm_stream_ps(uv + 2 * x, _mm256_castps256_ps128(lo));
    _mm_stream_ps(uv + 2 * x + 4, _mm256_castps256_ps128(hi));
    _mm_stream_ps(uv + 2 * x + 8, _mm256_extractf128_ps(lo, 1));
    _mm_stream_ps(uv + 2 * x + 12, _mm256_extractf128_ps(hi, 1));
    const __m256i seen = _mm256_castps_si256(_mm256_cmp_ps(there, d, _CMP_NLT_UQ));
    const __m256i bytes = _mm256_packs_epi16(_mm256_packs_epi32(seen, seen), _mm256_setzero_si256());
    _mm_storel_epi64(reinterpret_cast<__m128i*>(visible + x),
                     _mm_unpacklo_epi32(_mm256_castsi256_si128(bytes), _mm256_extracti128_si256(bytes, 1)));
  }
  _mm_sfence();
}

// What the flow kernel's memory traffic alone costs, both directions of a frame pair (the floor of
// BM_FlowForwardAndBackward*, whose kernel does its arithmetic on the same streams; memcpy of
// kFlowBytesPerPixel, BM_MemcpyFlowBytes, reads and writes each byte, twice this traffic).
void BM_FlowStreams(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx2")) {
    state.SkipWithError("no AVX2 on this CPU");
    return;
  }
  const size_t n = size_t(kW) * kH;
  std::vector<uint32_t> ids_a(n, 3), ids_b(n, 4);
  std::vector<float> depth_a(n, 20.0f), depth_b(n, 21.0f), uv_ab(2 * n), uv_ba(2 * n);
  std::vector<uint8_t> visible_ab(n), visible_ba(n);
  for (auto _ : state) {
    flowStreams(ids_a.data(), depth_a.data(), depth_b.data(), n, uv_ab.data(), visible_ab.data());
    flowStreams(ids_b.data(), depth_b.data(), depth_a.data(), n, uv_ba.data(), visible_ba.data());
    benchmark::DoNotOptimize(uv_ab.data());
    benchmark::DoNotOptimize(uv_ba.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * 2 * n * (4 + 4 + 4 + 8 + 1));
}
#endif

// The instruction path named by a benchmark argument (0 widest, 1 AVX-512, 2 AVX2, 3 one pixel at
// a time, 4 AVX-512 VBMI), shown in the benchmark's label as the path actually taken on this CPU.
Instructions instructionsArg(benchmark::State& state, int64_t arg) {
  static const char* const names[] = {"widest", "avx512", "avx2", "scalar", "avx512vbmi"};
  const auto requested = static_cast<Instructions>(arg);
  state.SetLabel(names[static_cast<int>(instructionsUsed(requested))]);
  return requested;
}

FlowOptions flowPath(benchmark::State& state, int64_t arg) {
  FlowOptions options;
  options.instructions = instructionsArg(state, arg);
  return options;
}

void BM_FlowForwardAndBackward(benchmark::State& state) {
  const int deformed_every = static_cast<int>(state.range(0));
  const FlowOptions options = flowPath(state, state.range(1));
  const CaptureFrame a = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, nullptr, deformed_every);
  const CaptureFrame b = bench::syntheticFrame(kW, kH, kObjects, kParts, 1, nullptr, deformed_every);
  MeshRegistry meshes;
  for (const auto& d : a.draws) meshes.add(bench::syntheticMesh(d.mesh_key));
  std::vector<int32_t> ids(a.draws.size());
  for (size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<int32_t>(k / kParts + 1);
  const auto fwd_map = associateDraws(a, ids, b, ids), bwd_map = associateDraws(b, ids, a, ids);
  const std::vector<float> depth(size_t(kW) * kH, 20.0f);
  FlowField fwd, bwd;
  for (auto _ : state) {
    computeFlow(a, b, fwd_map, depth, meshes, fwd, options);
    computeFlow(b, a, bwd_map, depth, meshes, bwd, options);
    benchmark::DoNotOptimize(fwd.uv.data());
    benchmark::DoNotOptimize(bwd.uv.data());
  }
  state.SetBytesProcessed(state.iterations() * 2 * size_t(kW) * kH * kFlowBytesPerPixel);
}

// The flow node's two flows of a frame from the depth topic's metres, both ways: argument 0 as it
// did until 2026-11-26 (each frame's metres turned back into window depth, windowDepthFromMetres,
// then flow from window depth), 1 as it does now (flow reads the metres where they are).
void BM_FlowFromMetres(benchmark::State& state) {
  const bool direct = state.range(0) == 1;
  state.SetLabel(direct ? "metres read as they are" : "window depth from metres first");
  const CaptureFrame a = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, nullptr);
  const CaptureFrame b = bench::syntheticFrame(kW, kH, kObjects, kParts, 1, nullptr);
  std::vector<int32_t> ids(a.draws.size());
  for (size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<int32_t>(k / kParts + 1);
  const auto fwd_map = associateDraws(a, ids, b, ids), bwd_map = associateDraws(b, ids, a, ids);
  const std::vector<float> metres_a = depthMetres(a, nullptr), metres_b = depthMetres(b, nullptr);
  const size_t n = a.pixelCount();
  std::vector<float> window_a(n), window_b(n), uv(2 * n);
  std::vector<uint8_t> visible(n);
  FlowFramePixels pa = flowFramePixels(a), pb = flowFramePixels(b);
  const MeshRegistry meshes;
  FlowStats stats;
  for (auto _ : state) {
    if (direct) {
      pa.depth_window = pb.depth_window = nullptr;
      pa.depth_metres = metres_a.data(), pb.depth_metres = metres_b.data();
    } else {
      windowDepthFromMetres(a.draws, a.draw_ids.data(), metres_a.data(), n, nullptr, window_a);
      windowDepthFromMetres(b.draws, b.draw_ids.data(), metres_b.data(), n, nullptr, window_b);
      pa.depth_window = window_a.data(), pb.depth_window = window_b.data();
    }
    computeFlow(pa, pb, fwd_map, metres_b.data(), meshes, uv.data(), visible.data(), FlowOptions(), &stats);
    computeFlow(pb, pa, bwd_map, metres_a.data(), meshes, uv.data(), visible.data());
    benchmark::DoNotOptimize(uv.data());
  }
  state.counters["rigid"] = static_cast<double>(stats.rigid);
  state.SetBytesProcessed(state.iterations() * 2 * size_t(kW) * kH * kFlowBytesPerPixel);
}

// The class pictures (semantic_overlay.h) and depth conversions (camera_model.h) of a synthetic
// frame: argument 0 the path (as flowPath), argument 1 the draws: 0 the synthetic frames' parts,
// which alternate every 8 pixels, 1 whole objects (one draw a tile, rows of ~100 pixels, as in a
// real capture). Next to memcpy of their output (rgb8, float).
CaptureFrame pixelFrame(benchmark::State& state) {
  CaptureFrame f = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, nullptr);
  if (state.range(1) == 1)
    for (uint32_t& id : f.draw_ids) id = 1 + (id - 1) / kParts * kParts;
  return f;
}

// Each draw's class, a fifth of them 0 (unlabeled): runs as long as the draws'.
std::vector<uint8_t> classIds(const CaptureFrame& f) {
  std::vector<uint8_t> ids(f.draw_ids.size());
  for (size_t i = 0; i < ids.size(); ++i)
    ids[i] = static_cast<uint8_t>(f.draw_ids[i] % 5 == 0 ? 0 : 1 + f.draw_ids[i] % 31);
  return ids;
}

ClassTable benchClasses() { return ClassTable::load(VIPER_SOURCE_DIR "/config/viper_classes.csv"); }

void BM_MemcpyRgbImage(benchmark::State& state) { copyBytes(state, size_t(kW) * kH * 3); }
void BM_MemcpyFloatImage(benchmark::State& state) { copyBytes(state, size_t(kW) * kH * 4); }

void BM_ColorizeClasses(benchmark::State& state) {
  const Instructions path = instructionsArg(state, state.range(0));
  const std::vector<uint8_t> ids = classIds(pixelFrame(state));
  const ClassTable classes = benchClasses();
  std::vector<uint8_t> rgb(3 * ids.size());
  for (auto _ : state) {
    colorizeClasses(ids.data(), ids.size(), classes, rgb.data(), path);
    benchmark::DoNotOptimize(rgb.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * rgb.size());
}

// VIPER's instance picture (instances_viper) of a frame's classes and track ids: argument 0 the path.
void BM_EncodeViperInstances(benchmark::State& state) {
  const Instructions path = instructionsArg(state, state.range(0));
  const CaptureFrame f = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, nullptr);
  const std::vector<uint8_t> classes = classIds(f);
  std::vector<int32_t> tracks(f.draw_ids.size());
  for (size_t i = 0; i < tracks.size(); ++i) tracks[i] = static_cast<int32_t>((f.draw_ids[i] + kParts - 1) / kParts);
  std::vector<uint8_t> rgb(3 * tracks.size());
  for (auto _ : state) {
    encodeViperInstances(classes.data(), tracks.data(), tracks.size(), rgb.data(), path);
    benchmark::DoNotOptimize(rgb.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * rgb.size());
}

void BM_OverlayClasses(benchmark::State& state) {
  const Instructions path = instructionsArg(state, state.range(0));
  const std::vector<uint8_t> ids = classIds(pixelFrame(state));
  const ClassTable classes = benchClasses();
  std::vector<uint8_t> color(3 * ids.size()), rgb(3 * ids.size());
  for (size_t i = 0; i < color.size(); ++i) color[i] = static_cast<uint8_t>(i * 7 + i / (3 * kW) * 13);
  for (auto _ : state) {
    overlayClasses(color.data(), ids.data(), ids.size(), classes, 0.5f, rgb.data(), path);
    benchmark::DoNotOptimize(rgb.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * rgb.size());
}

void BM_DepthMetres(benchmark::State& state) {
  const Instructions path = instructionsArg(state, state.range(0));
  const CaptureFrame f = pixelFrame(state);
  const auto camera = chooseFrameCamera(f);
  for (auto _ : state) {
    const std::vector<float> m = depthMetres(f, &*camera, path);
    benchmark::DoNotOptimize(m.data());
  }
  state.SetBytesProcessed(state.iterations() * f.pixelCount() * sizeof(float));
}

// The capture bridge's pass over a 1080p frame's depth, draw ids and primitive ids, in place in
// their messages: argument 0 the path (0 widest, 2 AVX2, 3 scalar), argument 1 is 0 for three passes
// (depthMetres, maskPrimitiveIds, largestDrawId), 1 for depthMetresMaskingPrimitives' one. The
// inputs are restored before each iteration, untimed.
void BM_BridgeDepthPass(benchmark::State& state) {
  const Instructions path = instructionsArg(state, state.range(0));
  const bool one_pass = state.range(1) == 1;
  const CaptureFrame f = bench::syntheticFrame(kW, kH, kObjects, kParts, 0, nullptr);
  const auto camera = chooseFrameCamera(f);
  const size_t n = f.pixelCount();
  std::vector<float> depth(n);
  std::vector<uint32_t> primitives(n);
  uint32_t largest = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(f.depth_window.begin(), f.depth_window.end(), depth.begin());
    std::copy(f.primitive_ids.begin(), f.primitive_ids.end(), primitives.begin());
    state.ResumeTiming();
    auto* masked = reinterpret_cast<int32_t*>(primitives.data());
    if (one_pass) {
      largest = depthMetresMaskingPrimitives(f, f.draw_ids.data(), depth.data(), &*camera, depth.data(), masked, path);
    } else {
      depthMetres(f, f.draw_ids.data(), depth.data(), &*camera, depth.data(), path);
      maskPrimitiveIds(f.draw_ids.data(), primitives.data(), n, masked);
      largest = largestDrawId(f.draw_ids.data(), n);
    }
    benchmark::DoNotOptimize(largest);
    benchmark::ClobberMemory();
  }
  static const char* const names[] = {"widest", "avx512", "avx2", "scalar", "avx512vbmi"};
  state.SetLabel(std::string(one_pass ? "one pass, " : "three passes, ") +
                 names[static_cast<int>(instructionsUsed(path))]);
  state.SetBytesProcessed(state.iterations() * n * 12);
}

void BM_WindowDepthFromMetres(benchmark::State& state) {
  const Instructions path = instructionsArg(state, state.range(0));
  const CaptureFrame f = pixelFrame(state);
  const auto camera = chooseFrameCamera(f);
  const std::vector<float> m = depthMetres(f, &*camera);
  size_t bad = 0;
  for (auto _ : state) {
    const std::vector<float> w = windowDepthFromMetres(f, m, &camera->projection, &bad, path);
    benchmark::DoNotOptimize(w.data());
  }
  state.counters["bad_px"] = static_cast<double>(bad);
  state.SetBytesProcessed(state.iterations() * f.pixelCount() * sizeof(float));
}

// The first `count` frames of the capture named by VIPER_BENCH_CAPTURE and the label table named
// by VIPER_BENCH_LABELS; false (the benchmark skipped, saying why) without them.
bool benchCapture(benchmark::State& state, size_t count, std::vector<CaptureFrame>& frames,
                  std::optional<LabelTable>& labels) {
  const char* path = std::getenv("VIPER_BENCH_CAPTURE");
  const char* labels_path = std::getenv("VIPER_BENCH_LABELS");
  if (!path || !labels_path) {
    state.SkipWithError("set VIPER_BENCH_CAPTURE and VIPER_BENCH_LABELS");
    return false;
  }
  CaptureReader reader(path);
  frames.resize(count);
  for (CaptureFrame& f : frames)
    if (reader.next(f) != CaptureReader::Status::kFrame) {
      state.SkipWithError("the capture has too few frames");
      return false;
    }
  labels = LabelTable::load(labels_path);
  return true;
}

// The same on two consecutive frames of a real capture (the world at 1920x1080, where a row of
// one draw runs ~100 px; the synthetic frames above alternate draws every 8 px). The capture is
// named by VIPER_BENCH_CAPTURE (scripts/measure_figures.sh makes it), its labels by
// VIPER_BENCH_LABELS; the benchmark is skipped without them.
void BM_FlowForwardAndBackwardCapture(benchmark::State& state) {
  std::vector<CaptureFrame> frames;
  std::optional<LabelTable> labels;
  if (!benchCapture(state, static_cast<size_t>(state.range(0)) + 1, frames, labels)) return;
  const FlowOptions options = flowPath(state, state.range(1));
  InstancePipeline pipeline(*labels);
  InstanceFrame objects;
  std::vector<int32_t> a_ids, b_ids;
  for (const CaptureFrame& f : frames) {  // tracking runs over every frame up to b
    pipeline.process(f, objects);
    std::swap(a_ids, b_ids);
    b_ids.assign(f.draws.size(), 0);
    for (const TrackedObject& o : objects.objects)
      for (uint32_t d : o.object.draws) b_ids[d] = o.track_id;
  }
  const CaptureFrame& a = frames[frames.size() - 2];
  const CaptureFrame& b = frames.back();
  const auto a_camera = chooseFrameCamera(a), b_camera = chooseFrameCamera(b);
  const std::vector<float> a_depth = depthMetres(a, a_camera ? &*a_camera : nullptr);
  const std::vector<float> b_depth = depthMetres(b, b_camera ? &*b_camera : nullptr);
  const auto fwd_map = associateDraws(a, a_ids, b, b_ids), bwd_map = associateDraws(b, b_ids, a, a_ids);
  FlowField fwd, bwd;
  FlowStats stats;
  for (auto _ : state) {
    computeFlow(a, b, fwd_map, b_depth, pipeline.meshes(), fwd, options, &stats);
    computeFlow(b, a, bwd_map, a_depth, pipeline.meshes(), bwd, options);
    benchmark::DoNotOptimize(fwd.uv.data());
    benchmark::DoNotOptimize(bwd.uv.data());
  }
  state.counters["rigid_px"] = static_cast<double>(stats.rigid);
  state.counters["non_rigid_px"] = static_cast<double>(stats.non_rigid);
  state.SetBytesProcessed(state.iterations() * 2 * size_t(a.width) * a.height * kFlowBytesPerPixel);
}

// Storage for a frame's four images in 8 sets taken in turn, as the bridge's recycled messages of
// 8 frames in flight (FrameImageMessages).
class RotatingImages : public CaptureImageSink {
 public:
  void* imageStorage(CaptureImage image, const CaptureFrame&, size_t bytes) override {
    std::vector<char>& v = sets_[set_][static_cast<int>(image)];
    v.resize(bytes);
    return v.data();
  }
  char* image(CaptureImage image) { return sets_[set_][static_cast<int>(image)].data(); }
  void next() { set_ = (set_ + 1) % kSets; }

 private:
  static constexpr int kSets = 8;
  std::vector<char> sets_[kSets][4];
  int set_ = 0;
};

// The capture bridge's kernels on each frame of a real capture (VIPER_BENCH_CAPTURE) in turn, as
// capture_bridge runs them: the frame read and its images decompressed straight into storage of
// the caller's (the bridge's messages), the frame camera chosen, then depth in metres, primitive ids
// masked and draw ids checked in one pass. At the capture's end the reader is opened again, untimed.
void BM_BridgeFrameCapture(benchmark::State& state) {
  const char* path = std::getenv("VIPER_BENCH_CAPTURE");
  if (!path) {
    state.SkipWithError("set VIPER_BENCH_CAPTURE");
    return;
  }
  RotatingImages images;
  auto open = [&] {
    auto reader = std::make_unique<CaptureReader>(path);
    reader->setImageSink(&images);
    return reader;
  };
  std::unique_ptr<CaptureReader> reader = open();
  CaptureFrame frame;
  uint32_t largest = 0;
  for (auto _ : state) {
    images.next();
    if (reader->next(frame) != CaptureReader::Status::kFrame) {
      state.PauseTiming();
      reader = open();
      state.ResumeTiming();
      if (reader->next(frame) != CaptureReader::Status::kFrame) {
        state.SkipWithError("the capture has no frame");
        return;
      }
    }
    const auto camera = chooseFrameCamera(frame);
    auto* depth = reinterpret_cast<float*>(images.image(CaptureImage::kDepth));
    const auto* ids = reinterpret_cast<const uint32_t*>(images.image(CaptureImage::kDrawIds));
    auto* primitives = reinterpret_cast<int32_t*>(images.image(CaptureImage::kPrimitiveIds));
    largest = depthMetresMaskingPrimitives(frame, ids, depth, camera ? &*camera : nullptr, depth, primitives);
    benchmark::DoNotOptimize(largest);
  }
  state.counters["width"] = frame.width;
}

// instances + tracking on 8 consecutive frames of a real capture (VIPER_BENCH_CAPTURE), looped
// with time running on.
void BM_InstancesAndTrackingCapture(benchmark::State& state) {
  std::vector<CaptureFrame> frames;
  std::optional<LabelTable> labels;
  if (!benchCapture(state, 8, frames, labels)) return;
  InstancePipelineOptions options;
  options.compute_boxes = false;  // as the instances node runs it
  InstancePipeline pipeline(*labels, options);
  InstanceFrame out;
  size_t i = 0;
  for (auto _ : state) {
    CaptureFrame& f = frames[i % frames.size()];
    f.time_s = static_cast<double>(i) / 15.0;
    pipeline.process(f, out);
    benchmark::DoNotOptimize(out.semantic.data());
    ++i;
  }
  state.counters["objects"] = static_cast<double>(out.objects.size());
}

// The instances node's pipeline with the pictures it publishes (semantic_color, instances_viper):
// argument 0 the frames (0 synthetic, parts alternating every 8 pixels; 1 the world capture of
// VIPER_BENCH_CAPTURE), argument 1 how the pictures are made (0 colorizeClasses and
// encodeViperInstances of the pipeline's images, 1 by the pipeline from its runs of draws).
void BM_InstancePictures(benchmark::State& state) {
  std::vector<CaptureFrame> frames;
  std::optional<LabelTable> labels;
  if (state.range(0) == 1) {
    if (!benchCapture(state, 8, frames, labels)) return;
  } else {
    labels.emplace();
    for (int s = 0; s < 8; ++s) frames.push_back(bench::syntheticFrame(kW, kH, kObjects, kParts, s, &*labels));
  }
  const bool from_runs = state.range(1) == 1;
  const ClassTable classes = benchClasses();
  InstancePipelineOptions options;
  options.compute_boxes = false;  // as the instances node runs it
  InstancePipeline pipeline(*labels, options);
  const size_t n = frames[0].pixelCount();
  std::vector<int32_t> ids(n);
  std::vector<uint8_t> color(3 * n), viper(3 * n);
  InstanceImagesInto into;
  into.instance_ids = ids.data();
  if (from_runs) into.semantic_color = color.data(), into.classes = &classes, into.instances_viper = viper.data();
  InstanceFrame out;
  size_t i = 0;
  for (auto _ : state) {
    CaptureFrame& f = frames[i % frames.size()];
    f.time_s = static_cast<double>(i) / 15.0;
    pipeline.process(f, out, into);
    if (!from_runs) {
      colorizeClasses(out.semantic.data(), n, classes, color.data());
      encodeViperInstances(out.semantic.data(), ids.data(), n, viper.data());
    }
    benchmark::DoNotOptimize(color.data());
    benchmark::DoNotOptimize(viper.data());
    ++i;
  }
  state.SetLabel(from_runs ? "pictures from runs" : "pictures from images");
}

// boxes: every thing object of a real capture's frame (VIPER_BENCH_CAPTURE, as above), from the
// mesh store; the world has ~200 objects, most with several parts of hundreds of vertices.
void BM_BoxesCapture(benchmark::State& state) {
  std::vector<CaptureFrame> frames;
  std::optional<LabelTable> labels;
  if (!benchCapture(state, static_cast<size_t>(state.range(0)) + 1, frames, labels)) return;
  InstancePipelineOptions options;
  options.compute_boxes = false;
  InstancePipeline pipeline(*labels, options);
  InstanceFrame objects;
  for (const CaptureFrame& f : frames) pipeline.process(f, objects);
  const CaptureFrame& frame = frames.back();
  size_t boxes = 0, vertices = 0;
  for (const TrackedObject& o : objects.objects) {
    if (!o.object.is_thing) continue;
    ++boxes;
    for (uint32_t d : o.object.draws)
      if (const MeshRecord* m = pipeline.meshes().find(frame.draws[d].mesh_key)) vertices += m->positions_xyz.size() / 3;
  }
  for (auto _ : state) {
    for (const TrackedObject& o : objects.objects) {
      if (!o.object.is_thing) continue;
      OrientedBox box = objectBox(frame, o.object, pipeline.meshes());
      benchmark::DoNotOptimize(box);
    }
  }
  state.counters["boxes"] = static_cast<double>(boxes);
  state.counters["vertices"] = static_cast<double>(vertices);
}

BENCHMARK(BM_MemcpyInstanceBytes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_InstancesAndTracking)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_InstancesAndTrackingCapture)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_InstancePictures)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BoxesCapture)->Arg(1)->Arg(20)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BridgeFrameCapture)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MemcpyFlowBytes)->Unit(benchmark::kMillisecond);
#ifdef __x86_64__
BENCHMARK(BM_FlowStreams)->Unit(benchmark::kMillisecond);
#endif
// {deformed every, path}: the widest path and AVX2 side by side.
BENCHMARK(BM_FlowForwardAndBackward)->ArgsProduct({{0, 3}, {0, 2}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FlowFromMetres)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
// {frame, path}: frames 1 -> 2 and 20 -> 21 of the capture, each path (AVX2 and one pixel at a time
// for comparison with the widest).
BENCHMARK(BM_FlowForwardAndBackwardCapture)->ArgsProduct({{1, 20}, {0, 2, 3}})->Unit(benchmark::kMillisecond);
// {path, draws}: (AVX-512 VBMI,) AVX-512, AVX2, one pixel at a time; parts of 8 pixels and whole
// objects.
BENCHMARK(BM_MemcpyRgbImage)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ColorizeClasses)->ArgsProduct({{4, 1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeViperInstances)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OverlayClasses)->ArgsProduct({{4, 1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MemcpyFloatImage)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DepthMetres)->ArgsProduct({{1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BridgeDepthPass)->ArgsProduct({{0, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WindowDepthFromMetres)->ArgsProduct({{1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace viper

BENCHMARK_MAIN();
