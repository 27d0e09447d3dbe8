// Writing the messages of real 1920x1080 ground-truth frames into a bag: rosbag (what a user's
// recorder uses) against the package's BagFileWriter (capture_to_bag, generate), with LZ4 and
// without compression, next to a memcpy of the same bytes. The messages come from a ground-truth
// bag made by generate and are held in memory as serialised bytes; each writer copies them into
// its bag (rosbag through its MessageInstance path, BagFileWriter into its chunk). CPU time is the
// writing thread's, kernel included (page cache or direct I/O).
// Run: scripts/bench_bag_writer.sh (makes the bag), or VIPER_BENCH_BAG=BAG rosrun viper bench_bag_writer
#include "viper/dataset/bag_file_writer.h"

#include <benchmark/benchmark.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <vector>

namespace {

struct Message {
  std::string topic;
  ros::Time time;
  std::vector<uint8_t> bytes;
  std::map<std::string, std::string> connection;
};

const std::vector<Message>& messages() {
  static const std::vector<Message> all = [] {
    const char* path = std::getenv("VIPER_BENCH_BAG");
    if (path == nullptr) {
      std::cerr << "bench_bag_writer: set VIPER_BENCH_BAG to a ground-truth bag (scripts/bench_bag_writer.sh)\n";
      std::exit(2);
    }
    std::vector<Message> out;
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      Message msg{m.getTopic(), m.getTime(), std::vector<uint8_t>(m.size()), *m.getConnectionHeader()};
      ros::serialization::OStream s(msg.bytes.data(), static_cast<uint32_t>(msg.bytes.size()));
      m.write(s);
      out.push_back(std::move(msg));
    }
    return out;
  }();
  return all;
}

uint64_t totalBytes() {
  uint64_t n = 0;
  for (const Message& m : messages()) n += m.bytes.size();
  return n;
}

std::string tempPath(const char* name) {
  return (std::filesystem::temp_directory_path() / ("bench_bag_writer_" + std::to_string(getpid()) + name)).string();
}

void counters(benchmark::State& state) {
  state.SetBytesProcessed(static_cast<int64_t>(totalBytes() * state.iterations()));
  state.counters["msg_MB"] = static_cast<double>(totalBytes()) / 1e6;
}

// rosbag writing raw messages (a ShapeShifter-like path: no deserialisation), 0 none, 1 LZ4.
void BM_Rosbag(benchmark::State& state) {
  counters(state);  // loads the messages (and stops with a message without VIPER_BENCH_BAG)
  const std::string path = tempPath("_rosbag.bag");
  // rosbag writes a MessageInstance's bytes as they are: the messages are read back once as such.
  rosbag::Bag source(std::getenv("VIPER_BENCH_BAG"), rosbag::bagmode::Read);
  rosbag::View view(source);
  std::vector<rosbag::MessageInstance> instances(view.begin(), view.end());
  for (auto _ : state) {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    if (state.range(0) == 1) bag.setCompression(rosbag::compression::LZ4);
    for (const rosbag::MessageInstance& m : instances) bag.write(m.getTopic(), m.getTime(), m, m.getConnectionHeader());
    bag.close();
  }
  state.counters["bag_MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  std::filesystem::remove(path);
  counters(state);
  state.SetLabel(state.range(0) ? "rosbag lz4" : "rosbag none");
}
BENCHMARK(BM_Rosbag)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// BagFileWriter: 0 none, 1 LZ4 (chunks that do not compress 1.5:1 stored plain), 2 LZ4 on every chunk.
void BM_BagFileWriter(benchmark::State& state) {
  const std::vector<Message>& all = messages();
  const std::string path = tempPath("_viper.bag");
  viper::dataset::BagFileOptions options;
  options.compression = state.range(0) == 0 ? viper::dataset::BagCompression::kNone : viper::dataset::BagCompression::kLz4;
  if (state.range(0) == 2) options.min_ratio = 1.0;
  for (auto _ : state) {
    viper::dataset::BagFileWriter bag(path, options);
    std::map<std::string, uint32_t> connections;
    for (const Message& m : all) {
      auto c = connections.find(m.topic);
      if (c == connections.end()) c = connections.emplace(m.topic, bag.addConnection(m.topic, m.connection)).first;
      std::memcpy(bag.beginMessage(c->second, m.time.sec, m.time.nsec, static_cast<uint32_t>(m.bytes.size())),
                  m.bytes.data(), m.bytes.size());
    }
    bag.close();
  }
  state.counters["bag_MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  std::filesystem::remove(path);
  counters(state);
  state.SetLabel(state.range(0) == 0 ? "viper none" : state.range(0) == 1 ? "viper lz4" : "viper lz4 every chunk");
}
BENCHMARK(BM_BagFileWriter)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The same bytes copied once in memory: the floor of any writer.
void BM_MemcpySameBytes(benchmark::State& state) {
  std::vector<uint8_t> into(totalBytes());
  for (auto _ : state) {
    size_t at = 0;
    for (const Message& m : messages()) {
      std::memcpy(into.data() + at, m.bytes.data(), m.bytes.size());
      at += m.bytes.size();
    }
    benchmark::DoNotOptimize(into.data());
  }
  counters(state);
}
BENCHMARK(BM_MemcpySameBytes)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
