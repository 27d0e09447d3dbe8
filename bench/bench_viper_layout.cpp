// Batch conversion of VIPER's layout into a bag (convertViperToBag, what viper_to_bag runs) against
// rosbag writing the very same messages from memory, on 6 synthetic 1920x1080 frames of every
// modality; and the cost of reading one file of each modality. Run: rosrun viper bench_viper_layout
// The bags go to the system's temporary folder (about 330 MB each, removed).
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/ros/dataset/viper_bag_conversion.h"

#include <benchmark/benchmark.h>
#include <rosbag/bag.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

namespace {

namespace fs = std::filesystem;
using namespace viper;
using namespace viper::dataset;

constexpr uint32_t kW = 1920, kH = 1080;
constexpr uint64_t kFrames = 6;

std::string tempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("bench_viper_layout_" + std::to_string(getpid()) + "_" + name)).string();
}

// A street-like frame: sky, buildings, road, cars; camera images with texture noise (what makes
// real PNGs large), label images in regions, smooth ego-motion flow with a NaN sky.
void writeFrame(const std::string& root, uint64_t f, std::mt19937& rng) {
  std::uniform_int_distribution<int> noise(-12, 12);
  Image8 img{kW, kH, 3, std::vector<uint8_t>(size_t(kW) * kH * 3)};
  Image8 cls{kW, kH, 1, std::vector<uint8_t>(size_t(kW) * kH)};
  Image8 inst{kW, kH, 3, std::vector<uint8_t>(size_t(kW) * kH * 3)};
  FlowImage flow{kW, kH, std::vector<float>(size_t(kW) * kH * 2)};
  const float horizon = kH * 0.45f;
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const size_t i = size_t(y) * kW + x;
      const bool car = (x / 240) % 2 == 1 && y > horizon + 60 && y < horizon + 200;
      const uint8_t c = y < horizon ? ((x + 7 * f) % 640 < 200 ? 9 : 2) : car ? 24 : 3;
      cls.data[i] = c;
      const int id = car ? 1 + static_cast<int>(x / 480) : 0;
      inst.data[3 * i] = c, inst.data[3 * i + 1] = static_cast<uint8_t>(id >> 8), inst.data[3 * i + 2] = static_cast<uint8_t>(id);
      for (int k = 0; k < 3; ++k)
        img.data[3 * i + k] = static_cast<uint8_t>(std::clamp(40 * k + c * 5 + static_cast<int>(y / 8) + noise(rng), 0, 255));
      float u = NAN, v = NAN;
      if (y > horizon) {
        const float inv_depth = (y - horizon) / (kH - horizon);
        u = (x - kW / 2.0f) * 0.02f * inv_depth, v = (y - horizon) * 0.02f * inv_depth;
      }
      if (car) u = 3.5f + 0.001f * x, v = -0.25f;
      flow.uv[2 * i] = u, flow.uv[2 * i + 1] = v;
    }
  writeViperColorImage(viperFramePath(root, "train", "img", "001", f, "png"), img);
  writeViperClassImage(viperFramePath(root, "train", "cls", "001", f, "png"), cls, {{{0, 0, 0}}, {{111, 74, 0}}});
  writeViperInstanceImage(viperFramePath(root, "train", "inst", "001", f, "png"), inst);
  writeViperFlow(viperFramePath(root, "train", "flow", "001", f, "npz"), flow);
  writeViperFlow(viperFramePath(root, "train", "flowbw", "001", f, "npz"), flow);
  std::vector<ViperBoxRow> boxes(20);
  for (size_t k = 0; k < boxes.size(); ++k) {
    boxes[k].class_id = 24, boxes[k].instance_id = static_cast<int64_t>(k + 1);
    boxes[k].box_3d = {{-2, -1, -1, 2, 1, 1}};
    boxes[k].model_to_camera[3] = static_cast<double>(k), boxes[k].model_to_camera[11] = -20;
  }
  writeViperBoxesCsv(viperFramePath(root, "train", "bb", "001", f, "csv"), boxes);
}

const std::string& benchLayout() {
  static const std::string root = [] {
    const std::string r = tempPath("layout");
    for (const char* m : {"img", "cls", "inst", "flow", "flowbw", "bb"}) fs::create_directories(fs::path(r) / "train" / m / "001");
    fs::create_directories(fs::path(r) / "train" / "camera");
    std::mt19937 rng(3);
    std::vector<ViperCameraRow> camera;
    for (uint64_t f = 0; f < kFrames; ++f) {
      writeFrame(r, f, rng);
      ViperCameraRow row;
      row.frame = f;
      row.projection = {{1.0, 0, 0, 0, 0, 1.78, 0, 0, 0, 0, -1.0004, -0.2, 0, 0, -1, 0}};
      row.view[11] = 0.5 * static_cast<double>(f);
      camera.push_back(row);
    }
    writeViperCameraCsv(viperCameraPath(r, "train", "001"), camera);
    std::atexit([] { fs::remove_all(tempPath("layout")); });
    return r;
  }();
  return root;
}

void BM_LayoutToBag(benchmark::State& state) {
  ViperToBagOptions o;
  o.root = benchLayout();
  o.prefetch = static_cast<int>(state.range(0));
  const std::string bag = tempPath("to.bag");
  ViperToBagStats stats;
  for (auto _ : state) stats = convertViperToBag(o, bag, nullptr, nullptr);
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(stats.frames * state.iterations()),
                                                      benchmark::Counter::kIsRate);
  state.counters["msg_MB"] = stats.message_bytes / 1e6;
  state.SetBytesProcessed(static_cast<int64_t>(stats.message_bytes * state.iterations()));
  fs::remove(bag);
}
BENCHMARK(BM_LayoutToBag)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// The same messages, built once, written by rosbag alone: the floor for any conversion.
void BM_RosbagWriteSameMessages(benchmark::State& state) {
  const ViperSequenceFiles files = scanViperSequence(benchLayout(), "train", "001");
  std::vector<std::string> problems;
  const auto camera = readViperCameraCsv(files.camera_csv, problems);
  ViperMessageBuilder builder(ViperTfFrames{}, nullptr);
  std::vector<ViperFrameMessages> frames;
  const std::set<ViperModality> all(allViperModalities().begin(), allViperModalities().end());
  for (uint64_t f : viperSequenceFrames(files, camera))
    frames.push_back(builder.build(readViperFrame(files, f, camera, all, problems), ros::Time(1.0 + f / 15.0),
                                   ViperTopicSelection{}));
  const std::string bag_path = tempPath("same.bag");
  uint64_t bytes = 0;
  for (auto _ : state) {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    bytes = 0;
    for (const ViperFrameMessages& m : frames) {
      const ros::Time t = m.color->header.stamp;
      auto write = [&](const std::string& topic, const auto& msg) {
        if (!msg) return;
        bag.write(topic, t, *msg);
        bytes += ros::serialization::serializationLength(*msg);
      };
      write("/capture/color/image_raw", m.color);
      write("/capture/color/camera_info", m.camera_info);
      write("/ground_truth/semantic", m.semantic);
      write("/ground_truth/instance_ids", m.instance_ids);
      write("/ground_truth/instances_viper", m.instances_viper);
      write("/ground_truth/flow/forward", m.flow_forward);
      write("/ground_truth/flow/backward", m.flow_backward);
      write("/ground_truth/odom", m.odom);
      write("/ground_truth/boxes", m.boxes);
      write("/ground_truth/boxes_optical", m.boxes_optical);
    }
    bag.close();
  }
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames.size() * state.iterations()),
                                                      benchmark::Counter::kIsRate);
  state.counters["msg_MB"] = bytes / 1e6;
  state.SetBytesProcessed(static_cast<int64_t>(bytes * state.iterations()));
  fs::remove(bag_path);
}
BENCHMARK(BM_RosbagWriteSameMessages)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// Reading one file of a modality (decode included).
void BM_ReadOneFile(benchmark::State& state) {
  const ViperModality m = allViperModalities()[static_cast<size_t>(state.range(0))];
  const ViperSequenceFiles files = scanViperSequence(benchLayout(), "train", "001");
  std::vector<std::string> problems;
  for (auto _ : state) benchmark::DoNotOptimize(readViperFrame(files, 1, {}, {m}, problems));
  state.SetLabel(viperModalityName(m));
  state.counters["file_MB"] = fs::file_size(files.files.at(m).at(1)) / 1e6;
}
BENCHMARK(BM_ReadOneFile)->DenseRange(0, 5)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
