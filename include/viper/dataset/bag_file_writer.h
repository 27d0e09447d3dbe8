// A writer of ROS bag files (format 2.0, http://wiki.ros.org/Bags/Format/2.0) that rosbag, `rosbag
// info/play/check`, Python's rosbag and bag_player read as they read rosbag's own. It exists for
// speed: a 1920x1080 ground-truth frame is ~93 MB of messages, and rosbag's writer copies each
// message twice and checksums its LZ4 chunks with roslz4's slow xxhash (110 ms of CPU a frame in
// generate). Here a message is serialised once, straight into the open chunk; LZ4 chunks are LZ4
// frames from liblz4 (its own fast checksum); and a chunk that does not compress (float optical
// flow: 1.35:1 for half of LZ4's time) is stored as it is, each chunk saying which in its header.
// ROS-free: connections are given as their header fields, messages as serialised bytes.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

struct LZ4F_cctx_s;

namespace viper::dataset {

namespace detail {
class DirectFile;
}

enum class BagCompression { kNone, kLz4, kBz2 };

/// "none", "lz4" or "bz2"; throws std::invalid_argument naming the text otherwise.
BagCompression bagCompressionFromName(const std::string& name);

struct BagFileOptions {
  BagCompression compression = BagCompression::kLz4;
  /// A chunk is closed when it holds more than this many bytes (rosbag's default).
  uint32_t chunk_threshold = 768 * 1024;
  /// A chunk is compressed only if samples of it compress at least this much (1.0: always).
  double min_ratio = 1.5;
};

/// Bytes that resize() leaves as they are (a chunk's message space is filled by the caller: zeroing
/// 93 MB a frame first would cost ~5 ms).
template <typename T>
struct NoInitAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = NoInitAllocator<U>;
  };
  NoInitAllocator() = default;
  template <typename U>
  NoInitAllocator(const NoInitAllocator<U>&) {}
  template <typename U>
  void construct(U* p) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
using ChunkBytes = std::vector<uint8_t, NoInitAllocator<uint8_t>>;

class BagFileWriter {
 public:
  /// Creates (truncates) `path`. Throws std::runtime_error "PATH: cannot write bag: REASON".
  BagFileWriter(const std::string& path, const BagFileOptions& options = {});
  /// Closes the bag if close() was not called; errors are then lost (call close() to see them).
  ~BagFileWriter();
  BagFileWriter(const BagFileWriter&) = delete;
  BagFileWriter& operator=(const BagFileWriter&) = delete;

  /// A connection: `fields` are its connection header (topic, type, md5sum, message_definition,
  /// callerid, latching). Returns its id for beginMessage().
  uint32_t addConnection(const std::string& topic, const std::map<std::string, std::string>& fields);

  /// Space for a message of `size` bytes on `connection` at time sec.nsec (not 0.0, which rosbag
  /// refuses), to be filled before the next call; the message is then in the bag.
  /// `bulk_offset` (0: none): where the message's bulk begins (an image's pixels). In an LZ4 chunk
  /// a bulk of at least kMinBulkBytes starts a block of its own, so that a reader can decompress
  /// it straight into a message of its own (BagBulkSink); any LZ4 reader reads the frame as usual.
  uint8_t* beginMessage(uint32_t connection, uint32_t sec, uint32_t nsec, uint32_t size, uint32_t bulk_offset = 0);
  static constexpr uint32_t kMinBulkBytes = 64 * 1024;

  /// Writes what is open and the index; the bag is complete. Throws as the constructor does.
  void close();

  const std::string& path() const { return path_; }

 private:
  struct Connection {
    std::string topic;
    std::map<std::string, std::string> fields;
    bool in_bag = false;  // its record written into a chunk already
  };
  struct IndexEntry {
    uint32_t sec, nsec, offset;
  };
  struct ChunkInfo {
    uint64_t position;
    uint32_t start_sec, start_nsec, end_sec, end_nsec;
    std::map<uint32_t, uint32_t> counts;  // connection -> messages (set when the chunk closes)
  };

  void finishMessage();
  void closeChunk();
  // The open chunk as an LZ4 frame into compressed_; returns its size.
  size_t compressLz4Frame();
  size_t compressLz4Blocks();
  template <typename Bytes>
  void writeConnectionRecord(Bytes& out, uint32_t id) const;
  void put(const void* bytes, size_t size);

  std::string path_;
  BagFileOptions options_;
  std::unique_ptr<detail::DirectFile> file_;  // written around the page cache where it can be
  std::vector<Connection> connections_;
  ChunkBytes chunk_;  // the open chunk, uncompressed; empty: none open
  ChunkBytes compressed_;
  std::vector<size_t> block_starts_;  // where in the open chunk a bulk starts (an LZ4 block)
  std::unique_ptr<LZ4F_cctx_s, size_t (*)(LZ4F_cctx_s*)> lz4_{nullptr, nullptr};  // made when first needed
  bool message_open_ = false;  // beginMessage's space not yet taken as filled
  ChunkInfo current_{};
  std::map<uint32_t, std::vector<IndexEntry>> chunk_index_;  // the open chunk's messages
  std::vector<ChunkInfo> chunk_infos_;
  bool closed_ = false;
};

}  // namespace viper::dataset
