// Reading a bag as bag_player plays it: rosbag::View with each message instantiated (bag_player
// before) against BagFileReader with each message deserialised from its bytes in the chunk
// (bag_player now), and BagFileReader's reading alone. Messages are typed as bag_player types them
// (Image, CameraInfo, DrawList, MeshStore; other types into a ShapeShifter). Reported a frame (the
// messages of one bag time): the reading thread's CPU time and the wall time, from the page cache.
// BM_BagFileReaderBulkSink reads as bag_player does now: each large message's bulk (an image's
// pixels) decompressed straight into storage of the reader's sink (one buffer a topic, reused).
// BM_Xxh32* (no bag needed): the content checksums of two 8 MB chunks, one after the other with
// libxxhash's XXH32 (as liblz4 and rosbag check them) and side by side (xxh32_streams, the reader's).
// Run: VIPER_BENCH_BAG=BAG rosrun viper bench_bag_reader, BAG a ground-truth bag
// (scripts/bench_bag_writer.sh makes one) or a raw bag (capture_to_bag, as scripts/measure_pipeline.sh).
#include "viper/dataset/bag_file_reader.h"

#include "../src/dataset/bag/xxh32_streams.h"

#include <benchmark/benchmark.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <topic_tools/shape_shifter.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>

#include <time.h>
#include <xxhash.h>

#include <array>
#include <chrono>
#include <cstdlib>
#include <map>
#include <iostream>
#include <set>

namespace {

const char* bagPath() {
  const char* path = std::getenv("VIPER_BENCH_BAG");
  if (path == nullptr) {
    std::cerr << "bench_bag_reader: set VIPER_BENCH_BAG to a bag (scripts/bench_bag_writer.sh, capture_to_bag)\n";
    std::exit(2);
  }
  return path;
}

double threadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// Runs `pass` (one reading of the whole bag, returning its frames) as the benchmark's iterations and
// reports ms a frame.
template <typename Pass>
void perFrame(benchmark::State& state, Pass&& pass) {
  double cpu_ms = 0.0, wall_ms = 0.0;
  uint64_t frames = 0;
  for (auto _ : state) {
    const double cpu = threadCpuMs();
    const auto wall = std::chrono::steady_clock::now();
    frames += pass();
    cpu_ms += threadCpuMs() - cpu;
    wall_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall).count();
  }
  state.counters["frames"] = static_cast<double>(frames) / static_cast<double>(state.iterations());
  state.counters["cpu_ms_per_frame"] = cpu_ms / static_cast<double>(frames);
  state.counters["wall_ms_per_frame"] = wall_ms / static_cast<double>(frames);
}

// A message of `type` made by `make` as bag_player types it; false for the ShapeShifter's types.
template <typename Make>
bool typed(const std::string& type, Make&& make) {
  if (type == "sensor_msgs/Image") benchmark::DoNotOptimize(make(sensor_msgs::Image()));
  else if (type == "sensor_msgs/CameraInfo") benchmark::DoNotOptimize(make(sensor_msgs::CameraInfo()));
  else if (type == "viper/DrawList") benchmark::DoNotOptimize(make(viper::DrawList()));
  else if (type == "viper/MeshStore") benchmark::DoNotOptimize(make(viper::MeshStore()));
  else return false;
  return true;
}

void BM_RosbagViewInstantiate(benchmark::State& state) {
  perFrame(state, [] {
    rosbag::Bag bag(bagPath(), rosbag::bagmode::Read);
    std::set<ros::Time> times;
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      times.insert(m.getTime());
      if (!typed(m.getDataType(), [&](auto type) { return m.instantiate<decltype(type)>(); }))
        benchmark::DoNotOptimize(m.instantiate<topic_tools::ShapeShifter>());
    }
    return times.size();
  });
}
BENCHMARK(BM_RosbagViewInstantiate)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// One reading of the bag by BagFileReader, use(message) for each message; returns its frames.
template <typename Use>
size_t readerPass(Use&& use, viper::dataset::BagBulkSink* sink = nullptr) {
  viper::dataset::BagFileReader bag(bagPath());
  bag.setBulkSink(sink);
  viper::dataset::BagMessage m;
  std::set<std::pair<uint32_t, uint32_t>> times;
  while (bag.next(m)) {
    times.emplace(m.sec, m.nsec);
    use(m);
  }
  return times.size();
}

void BM_BagFileReaderDeserialise(benchmark::State& state) {
  perFrame(state, [] {
    return readerPass([](const viper::dataset::BagMessage& m) {
      ros::serialization::IStream in(const_cast<uint8_t*>(m.data), m.size);
      const std::string& type = m.connection->field("type");
      if (typed(type, [&](auto message) {
            const auto p = boost::make_shared<decltype(message)>();
            ros::serialization::deserialize(in, *p);
            return p;
          }))
        return;
      const auto shape = boost::make_shared<topic_tools::ShapeShifter>();
      shape->morph(m.connection->field("md5sum"), type, m.connection->field("message_definition"),
                   m.connection->field("latching"));
      shape->read(in);
      benchmark::DoNotOptimize(shape);
    });
  });
}
BENCHMARK(BM_BagFileReaderDeserialise)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The reading alone (chunks read and decompressed, messages found): what deserialising adds is the
// difference to the benchmark above.
void BM_BagFileReaderBytesOnly(benchmark::State& state) {
  perFrame(state, [] { return readerPass([](const viper::dataset::BagMessage& m) { benchmark::DoNotOptimize(m.data); }); });
}
BENCHMARK(BM_BagFileReaderBytesOnly)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// Takes every bulk at the first block boundary it is shown (in BagFileWriter's bags, where an
// image's pixels start), into one buffer a topic; two, as the reader reads a chunk ahead.
struct ReusedStorage : viper::dataset::BagBulkSink {
  uint8_t* bulk(const viper::dataset::BagConnection& connection, const uint8_t*, uint32_t available, uint32_t size,
                uint32_t& offset) override {
    offset = available;
    auto& [buffers, turn] = storage[connection.topic];
    std::vector<uint8_t>& b = buffers[turn ^= 1];
    if (b.size() < size - offset + 1) b.resize(size - offset + 1);
    return b.data();
  }
  std::map<std::string, std::pair<std::array<std::vector<uint8_t>, 2>, int>> storage;
};

void BM_BagFileReaderBulkSink(benchmark::State& state) {
  ReusedStorage sink;
  perFrame(state, [&] { return readerPass([](const viper::dataset::BagMessage& m) { benchmark::DoNotOptimize(m.data); }, &sink); });
}
BENCHMARK(BM_BagFileReaderBulkSink)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// Two 8 MB chunks of noise (they do not compress: the hash's own speed).
const std::vector<std::vector<uint8_t>>& twoChunks() {
  static const std::vector<std::vector<uint8_t>> chunks = [] {
    std::vector<std::vector<uint8_t>> c(2, std::vector<uint8_t>(8u << 20));
    uint32_t x = 1;
    for (auto& chunk : c)
      for (uint8_t& b : chunk) b = static_cast<uint8_t>((x = x * 1664525u + 1013904223u) >> 24);
    return c;
  }();
  return chunks;
}

void BM_Xxh32OneAfterTheOther(benchmark::State& state) {
  const auto& c = twoChunks();
  for (auto _ : state) {
    benchmark::DoNotOptimize(XXH32(c[0].data(), c[0].size(), 0));
    benchmark::DoNotOptimize(XXH32(c[1].data(), c[1].size(), 0));
  }
  state.SetBytesProcessed(state.iterations() * 2 * static_cast<int64_t>(c[0].size()));
}
BENCHMARK(BM_Xxh32OneAfterTheOther)->Unit(benchmark::kMillisecond);

void BM_Xxh32SideBySide(benchmark::State& state) {
  const auto& c = twoChunks();
  const std::vector<viper::dataset::detail::BytePiece> a = {{c[0].data(), c[0].size()}}, b = {{c[1].data(), c[1].size()}};
  uint32_t hashes[2];
  for (auto _ : state) {
    viper::dataset::detail::xxh32Streams({&a, &b}, hashes);
    benchmark::DoNotOptimize(hashes);
  }
  state.SetBytesProcessed(state.iterations() * 2 * static_cast<int64_t>(c[0].size()));
  state.SetLabel(viper::dataset::detail::xxh32StreamsKernel());
}
BENCHMARK(BM_Xxh32SideBySide)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
