// libFuzzer target: an arbitrary file as a ROS bag (BagFileReader, what bag_player plays). It must
// open and give its messages, or end in std::runtime_error naming the file; a message handed out
// lies inside its chunk (the fuzzer's ASan checks every byte of it is readable) and names a
// connection of the bag; a message's bulk that went to the sink (BagBulkSink, as bag_player's
// images) comes back whole in the sink's storage.
// Seeds: bags written by BagFileWriter, plain, LZ4 (compressible messages) and bz2, two topics; and
// LZ4 with a 70 kB message whose bulk starts a block (the sink's way).
#include "fuzz_support.h"
#include "viper/dataset/bag_file_reader.h"
#include "viper/dataset/bag_file_writer.h"

#include <algorithm>
#include <cstring>
#include <deque>
#include <stdexcept>
#include <vector>
#include <string>

namespace {

void writeBag(const std::string& path, viper::dataset::BagCompression compression) {
  using namespace viper::dataset;
  BagFileOptions options;
  options.compression = compression;
  options.chunk_threshold = 256;  // several chunks
  options.min_ratio = 1.0;        // compress every chunk
  BagFileWriter bag(path, options);
  const uint32_t a = bag.addConnection("/a", {{"type", "std_msgs/String"}, {"md5sum", "992ce8a1687cec8c8bd883ec73ca41d1"},
                                              {"message_definition", "string data\n"}, {"callerid", "/seed"}});
  const uint32_t b = bag.addConnection("/b", {{"type", "std_msgs/UInt8MultiArray"}, {"md5sum", "*"},
                                              {"message_definition", ""}, {"latching", "1"}});
  for (uint32_t i = 1; i <= 12; ++i) {
    const uint32_t size = 8 + 40 * (i % 3);
    uint8_t* m = bag.beginMessage(i % 2 ? a : b, i, i * 1000, size);
    std::memset(m, static_cast<int>('a' + i), size);
    std::memcpy(m, &size, 4);
  }
  bag.close();
}

void writeBulkBag(const std::string& path) {
  using namespace viper::dataset;
  BagFileWriter bag(path);
  const uint32_t c = bag.addConnection("/image", {{"type", "std_msgs/UInt8MultiArray"}, {"md5sum", "*"},
                                                  {"message_definition", ""}});
  for (uint32_t i = 1; i <= 2; ++i) {
    const uint32_t size = 70000;
    uint8_t* m = bag.beginMessage(c, i, 0, size, 16);
    for (uint32_t k = 0; k < size; ++k) m[k] = static_cast<uint8_t>(k / 300 + i);
  }
  bag.close();
}

// Takes every bulk offered from 8 bytes in (or all that were shown, if fewer).
struct Sink : viper::dataset::BagBulkSink {
  uint8_t* bulk(const viper::dataset::BagConnection&, const uint8_t*, uint32_t available, uint32_t size,
                uint32_t& offset) override {
    offset = std::min<uint32_t>(available, 8);
    storage.emplace_back(size - offset + 1);
    return storage.back().data();
  }
  std::deque<std::vector<uint8_t>> storage;
};

}  // namespace

void viper::fuzz::writeSeeds(const std::string& dir) {
  using viper::dataset::BagCompression;
  writeBag(dir + "/none.bag", BagCompression::kNone);
  writeBag(dir + "/lz4.bag", BagCompression::kLz4);
  writeBag(dir + "/bz2.bag", BagCompression::kBz2);
  writeBulkBag(dir + "/bulk.bag");
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".bag");
  try {
    viper::dataset::BagFileReader bag(path);
    Sink sink;
    bag.setBulkSink(&sink);
    viper::dataset::BagMessage m;
    size_t given = 0;
    uint64_t sum = 0;
    while (bag.next(m)) {
      if (!m.connection || (m.size > 0 && !m.data)) __builtin_trap();
      const uint32_t in_chunk = m.bulk ? m.bulk_offset : m.size;
      if (m.bulk && m.bulk_offset > m.size) __builtin_trap();
      for (uint32_t i = 0; i < in_chunk; ++i) sum += m.data[i];  // every byte readable
      for (uint32_t i = in_chunk; i < m.size; ++i) sum += m.bulk[i - in_chunk];
      if (++given > bag.messageCount()) __builtin_trap();
    }
    if (given != bag.messageCount()) __builtin_trap();
    (void)sum;
  } catch (const std::runtime_error&) {
  }
  return 0;
}
