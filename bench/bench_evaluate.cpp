// Per-frame cost of the evaluate node's core (the Evaluation calls) at 1920x1080 on one core, next
// to memcpy of the bytes each metric reads: semantic IoU, semantic iIoU, dense flow (all + noc), sparse flow, and
// instance AP with 30 predictions covering ~32 % of the frame, as box masks and as full-frame masks.
// Synthetic, deterministic frames; shapes only.
// Run: rosrun viper bench_evaluate --benchmark_repetitions=5
#include "memcpy_floor.h"

#include "viper/evaluation/evaluation.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

namespace viper {
namespace {

constexpr uint32_t kW = 1920, kH = 1080;
constexpr size_t kN = size_t(kW) * kH;
constexpr uint8_t kUnlabeled = 0, kSky = 2, kRoad = 3, kBuilding = 9, kPerson = 20, kCar = 24, kVan = 25,
                  kBus = 26;

ClassTable classes() { return ClassTable::load(VIPER_SOURCE_DIR "/config/viper_classes.csv"); }

// A deterministic generator (numerical recipes' LCG), so that every run scores the same frames.
struct Lcg {
  uint32_t state = 12345;
  uint32_t next(uint32_t k) { return (state = state * 1664525u + 1013904223u) / 256u % k; }
  float unit() { return static_cast<float>(next(1u << 20)) / (1u << 20); }
};

using bench::copyBytes;

// Background classes in bands (sky, buildings, road) with void patches.
std::vector<uint8_t> backgroundClasses() {
  std::vector<uint8_t> c(kN);
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      uint8_t v = y < kH / 4 ? kSky : y < kH / 2 ? kBuilding : kRoad;
      if ((x / 64 + y / 48) % 17 == 0) v = kUnlabeled;
      c[size_t(y) * kW + x] = v;
    }
  return c;
}

// semantic: reads ground truth and prediction (1 + 1 B/px).
void BM_MemcpySemanticBytes(benchmark::State& state) { copyBytes(state, kN * 2); }

void BM_Semantic(benchmark::State& state) {
  const std::vector<uint8_t> gt = backgroundClasses();
  std::vector<uint8_t> pred = gt;
  Lcg rnd;
  for (auto& p : pred)
    if (rnd.next(10) == 0) p = static_cast<uint8_t>(rnd.next(32));
  Evaluation e(classes());
  for (auto _ : state) e.addSemantic("day", gt.data(), pred.data(), kN);
  benchmark::DoNotOptimize(e.summarize().all.scoresOf("semantic").value("mean_iou"));
}

struct FlowFrame {
  std::vector<float> gt, pred;
  std::vector<uint8_t> visible;
};

// Smooth ground truth, undefined on the sky; 8 % occluded; 0.5 % NaN predictions. The other
// predictions are off by 0..8 px: by an error that varies smoothly over the frame (as an
// estimator's errors do, region by region), or, the worst case for branch prediction, by a random
// error at every pixel.
FlowFrame makeFlowFrame(bool random_errors) {
  FlowFrame f;
  f.gt.resize(2 * kN), f.pred.resize(2 * kN), f.visible.resize(kN);
  Lcg rnd;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const size_t i = size_t(y) * kW + x;
      const bool sky = y < kH / 8;
      f.gt[2 * i] = sky ? nan : 6.0f * std::sin(x / 100.0f);
      f.gt[2 * i + 1] = sky ? nan : 3.0f * std::cos(y / 80.0f);
      f.visible[i] = (x / 37 + y / 23) % 12 != 0;
      const float noise = rnd.unit(), turn = rnd.unit();
      const float r = random_errors ? 8.0f * noise : std::abs(4.0f + 4.0f * std::sin(x / 97.0f) * std::cos(y / 61.0f) + 0.3f * (noise - 0.5f));
      const float a = 6.2831853f * (random_errors ? turn : x / 640.0f + y / 360.0f + 0.02f * turn);
      const bool bad = rnd.next(200) == 0;
      f.pred[2 * i] = bad ? nan : (sky ? 0.0f : f.gt[2 * i]) + r * std::cos(a);
      f.pred[2 * i + 1] = bad ? nan : (sky ? 0.0f : f.gt[2 * i + 1]) + r * std::sin(a);
    }
  return f;
}

const FlowFrame& flowFrame(bool random_errors = false) {
  static const FlowFrame smooth = makeFlowFrame(false);
  if (!random_errors) return smooth;
  static const FlowFrame random = makeFlowFrame(true);
  return random;
}

// dense flow: reads ground truth (8 B/px), prediction (8) and visibility (1).
void BM_MemcpyFlowBytes(benchmark::State& state) { copyBytes(state, kN * (8 + 8 + 1)); }

// Arg: 0 smooth errors, 1 random errors.
void BM_DenseFlow(benchmark::State& state) {
  const FlowFrame& f = flowFrame(state.range(0) != 0);
  Evaluation e(classes());
  for (auto _ : state) e.addFlow("day", f.gt.data(), f.visible.data(), f.pred.data(), kN);
  benchmark::DoNotOptimize(e.summarize().all.scoresOf("flow").value("wauc"));
}

// sparse flow: 8100 vectors on a grid (opencv_apps' fback_flow with a 16 px step gives ~8100).
void BM_SparseFlow(benchmark::State& state) {
  const FlowFrame& f = flowFrame();
  std::vector<SparseFlowVector> vectors;
  Lcg rnd;
  for (int gy = 0; gy < 90; ++gy)
    for (int gx = 0; gx < 90; ++gx) {
      SparseFlowVector v;
      v.x = 10.0 + gx * 21.2, v.y = 5.0 + gy * 11.9;
      v.u = 4.0 * rnd.unit(), v.v = 2.0 * rnd.unit();
      vectors.push_back(v);
    }
  Evaluation e(classes());
  for (auto _ : state) e.addSparseFlow("day", f.gt.data(), f.visible.data(), kW, kH, vectors);
  benchmark::DoNotOptimize(e.summarize().all.scoresOf("flow_sparse").value("wauc"));
}

// 40 ground-truth instances (ellipses, ~34 % of the frame) plus 20 under 100 px; 30 predictions
// near the first 30 (shifted, resized, some of another class), ellipses in boxes covering ~32 %.
struct InstanceScene {
  std::vector<int32_t> ids;
  std::vector<uint8_t> classes;
  std::vector<std::vector<uint8_t>> box_masks;
  std::vector<BoxedInstance> boxes;
  std::vector<PredictedInstance> full;
  double box_fraction = 0.0;
};

void paintEllipse(uint32_t x0, uint32_t y0, uint32_t w, uint32_t h, const std::function<void(uint32_t, uint32_t)>& f) {
  const double cx = 0.5 * (w - 1), cy = 0.5 * (h - 1);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const double dx = (x - cx) / (0.5 * w), dy = (y - cy) / (0.5 * h);
      if (dx * dx + dy * dy <= 1.0) f(x0 + x, y0 + y);
    }
}

const InstanceScene& instanceScene() {
  static const InstanceScene s = [] {
    InstanceScene s;
    s.ids.assign(kN, 0);
    s.classes = backgroundClasses();
    Lcg rnd;
    const uint8_t kinds[] = {kCar, kVan, kBus, kPerson};
    struct Box {
      uint32_t x0, y0, w, h;
      uint8_t c;
    };
    std::vector<Box> gt;
    const uint32_t cell_w = kW / 8, cell_h = kH / 5;  // 240 x 216
    for (int k = 0; k < 40; ++k) {
      Box b;
      b.w = 190 + rnd.next(20), b.h = 128 + rnd.next(20), b.c = kinds[rnd.next(4)];
      b.x0 = (k % 8) * cell_w + rnd.next(cell_w - b.w), b.y0 = (k / 8) * cell_h + rnd.next(cell_h - b.h);
      gt.push_back(b);
      paintEllipse(b.x0, b.y0, b.w, b.h, [&](uint32_t x, uint32_t y) {
        s.ids[size_t(y) * kW + x] = 1 + k, s.classes[size_t(y) * kW + x] = b.c;
      });
    }
    for (int k = 0; k < 20; ++k) {  // small ones, ignored by the protocol
      const uint32_t x0 = rnd.next(kW - 8), y0 = rnd.next(kH - 8);
      for (uint32_t y = y0; y < y0 + 8; ++y)
        for (uint32_t x = x0; x < x0 + 8; ++x) s.ids[size_t(y) * kW + x] = 100 + k, s.classes[size_t(y) * kW + x] = kPerson;
    }
    size_t box_px = 0;
    for (int k = 0; k < 30; ++k) {
      const Box& g = gt[k];
      BoxedInstance b;
      b.class_id = rnd.next(6) == 0 ? kinds[rnd.next(4)] : g.c;
      b.score = 0.05 + 0.9 * rnd.unit();
      b.width = g.w - 45 + rnd.next(40), b.height = g.h - 27 + rnd.next(30);
      const int dx = static_cast<int>(rnd.next(31)) - 15, dy = static_cast<int>(rnd.next(21)) - 10;
      b.x0 = static_cast<uint32_t>(std::clamp<int>(static_cast<int>(g.x0) + dx, 0, static_cast<int>(kW - b.width)));
      b.y0 = static_cast<uint32_t>(std::clamp<int>(static_cast<int>(g.y0) + dy, 0, static_cast<int>(kH - b.height)));
      std::vector<uint8_t> m(size_t(b.width) * b.height, 0);
      paintEllipse(0, 0, b.width, b.height, [&](uint32_t x, uint32_t y) { m[size_t(y) * b.width + x] = 1; });
      PredictedInstance p;
      p.class_id = b.class_id, p.score = b.score;
      p.mask.assign(kN, 0);
      for (uint32_t y = 0; y < b.height; ++y)
        std::memcpy(&p.mask[size_t(b.y0 + y) * kW + b.x0], &m[size_t(y) * b.width], b.width);
      box_px += m.size();
      s.box_masks.push_back(std::move(m));
      s.boxes.push_back(b);
      s.full.push_back(std::move(p));
    }
    for (size_t k = 0; k < s.boxes.size(); ++k) s.boxes[k].mask = s.box_masks[k].data();
    s.box_fraction = static_cast<double>(box_px) / kN;
    return s;
  }();
  return s;
}

// instances: read ground-truth ids and classes (4 + 1 B/px) and every mask byte: the boxes' (box
// masks) or 30 frames' worth (full-frame masks).
void BM_MemcpyInstanceBoxBytes(benchmark::State& state) {
  const InstanceScene& s = instanceScene();
  copyBytes(state, kN * 5 + static_cast<size_t>(s.box_fraction * kN));
}

void BM_MemcpyInstanceFullFrameBytes(benchmark::State& state) { copyBytes(state, kN * (5 + 30)); }

void BM_InstancesBoxMasks(benchmark::State& state) {
  const InstanceScene& s = instanceScene();
  Evaluation e(classes());
  for (auto _ : state) e.addInstances("day", s.ids.data(), s.classes.data(), kW, kH, s.boxes);
  state.counters["box_fraction"] = s.box_fraction;
  benchmark::DoNotOptimize(e.summarize().all.scoresOf("instances").value("ap"));
}

void BM_InstancesFullFrameMasks(benchmark::State& state) {
  const InstanceScene& s = instanceScene();
  Evaluation e(classes());
  for (auto _ : state) e.addInstances("day", s.ids.data(), s.classes.data(), kN, s.full);
  state.counters["box_fraction"] = s.box_fraction;
  benchmark::DoNotOptimize(e.summarize().all.scoresOf("instances").value("ap"));
}

// semantic_iiou (a plug-in, through Evaluation::add): ground-truth classes and ids, and a
// prediction that is the ground truth with 10 % of its pixels changed (1 + 4 + 1 B/px).
void BM_MemcpySemanticIiouBytes(benchmark::State& state) { copyBytes(state, kN * 6); }

void BM_SemanticIiou(benchmark::State& state) {
  const InstanceScene& s = instanceScene();
  std::vector<uint8_t> pred = s.classes;
  Lcg rnd;
  for (auto& p : pred)
    if (rnd.next(10) == 0) p = static_cast<uint8_t>(rnd.next(32));
  EvalFrame f;
  f.condition = "day", f.width = kW, f.height = kH;
  f.gt_semantic = s.classes.data(), f.gt_instance_ids = s.ids.data(), f.pred_semantic = pred.data();
  Evaluation e(classes());
  for (auto _ : state) e.add("semantic_iiou", f);
  benchmark::DoNotOptimize(e.summarize().all.scoresOf("semantic_iiou").frames);
}

// Wall time: the instance accumulators may use a second thread.
BENCHMARK(BM_MemcpySemanticBytes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Semantic)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MemcpyFlowBytes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DenseFlow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SparseFlow)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MemcpyInstanceBoxBytes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_InstancesBoxMasks)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MemcpySemanticIiouBytes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SemanticIiou)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MemcpyInstanceFullFrameBytes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_InstancesFullFrameMasks)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace viper

BENCHMARK_MAIN();
