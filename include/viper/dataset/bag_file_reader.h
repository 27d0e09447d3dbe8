// A reader of ROS bag files (format 2.0, http://wiki.ros.org/Bags/Format/2.0), BagFileWriter's
// counterpart, for bag_player. It exists for speed: rosbag streams each LZ4 chunk through roslz4 (a
// 1080p raw bag: 22 ms of CPU a frame read and instantiated, half of it roslz4's xxhash). Here
// liblz4's frame API decompresses an LZ4 chunk straight into the chunk's buffer, and a message is
// handed out as its bytes in that buffer, for the caller to deserialise from there (18 ms a frame,
// bench_bag_reader). LZ4's content checksums are still verified, as rosbag does (with libxxhash's
// XXH32, 2.3 times as fast as liblz4's). A BagBulkSink may take the bulk of large messages (an
// image's pixels): the LZ4 blocks that hold it are decompressed straight into the sink's storage (a
// message of the caller's), not into the chunk to be copied from there again; BagFileWriter starts
// a block where an image's pixels start, so that every block of them goes there.
// The messages come in the order rosbag::View over the whole bag plays them: by time, and for equal
// times in file order (chunk position, then offset in the chunk). rosbag orders equal times of one
// connection so too; equal times across connections it orders as its sort happens to leave them.
// select() keeps the messages of some connections only (rosbag::View with a query), in the same
// order: chunks without any of them are never read. A damaged chunk is an error once, naming it and
// the messages of it skipped; reading then goes on after them (rosbag reads on after one too).
// ROS-free: connections are given as their header fields, messages as serialised bytes.
#pragma once

#include "viper/dataset/bag_file_writer.h"

#include <array>
#include <climits>
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace viper::dataset {

namespace detail {
class BagChunkDecoder;
class PreadFile;
struct DeferredChecksum;
}  // namespace detail

struct BagConnection {
  uint32_t id = 0;
  std::string topic;
  /// Its connection header: type, md5sum, message_definition, callerid, latching, ...
  std::map<std::string, std::string> fields;
  /// How many messages the bag's index holds for it (0: rosbag::View does not list it).
  uint64_t messages = 0;

  /// A field of its header, "" where it has none.
  const std::string& field(const std::string& name) const;
};

struct BagMessage {
  const BagConnection* connection = nullptr;
  uint32_t sec = 0, nsec = 0;
  /// The serialised message inside the decompressed chunk, valid until the reader's next call.
  const uint8_t* data = nullptr;
  uint32_t size = 0;
  /// Where not null: the message's bytes from `bulk_offset` on are at `bulk`, the storage the
  /// reader's BagBulkSink gave for them (decompressed there), and `data` holds only those before.
  const uint8_t* bulk = nullptr;
  uint32_t bulk_offset = 0;
};

/// A message as the bag's index has it: its connection and its time (its bytes not read).
struct BagIndexedMessage {
  const BagConnection* connection = nullptr;  // the reader's: valid while it lives
  uint32_t sec = 0, nsec = 0;
};

/// next()'s error for a damaged chunk. what(): the file, the chunk's byte offset, what is wrong and
/// how many messages are skipped. Those are the chunk's messages (of the selected connections) that
/// next() has not given, in play order; the next call goes on with the first message after them.
class BagDamagedChunk : public std::runtime_error {
 public:
  BagDamagedChunk(const std::string& what, uint64_t position, std::vector<BagIndexedMessage> skipped)
      : std::runtime_error(what), position_(position), skipped_(std::move(skipped)) {}
  /// The byte offset of the chunk's record.
  uint64_t position() const { return position_; }
  const std::vector<BagIndexedMessage>& skipped() const { return skipped_; }

 private:
  uint64_t position_;
  std::vector<BagIndexedMessage> skipped_;
};

/// Storage for the bulk of large messages (an image's pixels): an LZ4 chunk's blocks that fall in it
/// are decompressed straight there rather than into the chunk, to be copied out of it again.
class BagBulkSink {
 public:
  virtual ~BagBulkSink() = default;
  /// Asked, while the chunk is decompressed, for the last message of an LZ4 chunk that is at least
  /// kMinBulk bytes: `prefix` holds the first `available` of its `size` bytes (more at each call
  /// until an answer). Returns storage for its bytes from `offset` on (size - offset of them; set
  /// offset <= available), which stays the sink's; or nullptr: ask again once more bytes are in
  /// (and, if the message is not one to take, at each block: the sink says nullptr every time).
  /// The message then comes from next() with `bulk` set, unless the chunk turns out damaged.
  virtual uint8_t* bulk(const BagConnection& connection, const uint8_t* prefix, uint32_t available, uint32_t size,
                        uint32_t& offset) = 0;
  static constexpr uint32_t kMinBulk = 64 * 1024;
};

class BagFileReader {
 public:
  /// Opens `path` and reads its index. Throws std::runtime_error naming the file and what is wrong;
  /// a bag without an index (a recording that did not finish) says that `rosbag reindex` recovers it.
  explicit BagFileReader(const std::string& path);
  ~BagFileReader();
  BagFileReader(const BagFileReader&) = delete;
  BagFileReader& operator=(const BagFileReader&) = delete;

  /// Every connection of the bag's index, by id.
  const std::vector<BagConnection>& connections() const { return connections_; }
  /// The messages next() gives in all (of the selected connections).
  size_t messageCount() const { return entries_.size(); }

  /// Keeps only the messages of the connections `wanted` says true for (of those kept before), in
  /// the same order; chunks without any of them are not read. Before the first next() (else throws
  /// std::logic_error). connections() and their `messages` stay the whole bag's.
  void select(const std::function<bool(const BagConnection&)>& wanted);

  /// Hands the bulk of large messages to `sink` (nullptr: none), which must outlive the reader's use.
  void setBulkSink(BagBulkSink* sink) { sink_ = sink; }

  /// The next message; false after the last. For a damaged chunk, throws BagDamagedChunk (every
  /// message before it given; its own skipped), and the next call goes on after it. Throws
  /// std::runtime_error naming the file for a file that cannot be read.
  bool next(BagMessage& message);

  const std::string& path() const { return path_; }

 private:
  struct Chunk {
    uint64_t position;       // of its record
    uint64_t data_position;  // of its (compressed) data
    uint32_t data_size;      // stored
    uint32_t size;           // decompressed
    BagCompression compression;
    uint32_t last_entry = 0;  // the offset of its last indexed record (the one a sink may take)
    // That record's connection (UINT32_MAX: none indexed, or not selected: no sink for it).
    uint32_t last_connection = UINT32_MAX;
    bool skipped = false;  // found damaged: its messages not given
  };
  // A message in the index: its time, the chunk and its record's offset there, its connection
  // (an index into connections_).
  struct Entry {
    uint32_t sec, nsec, chunk, offset, connection;
  };
  // Decompressed chunks, a few: chunks of several topics may overlap in time.
  struct CachedChunk {
    uint32_t chunk = 0;
    uint64_t used = 0;  // when last asked for; 0: holds no chunk
    ChunkBytes bytes;  // the chunk, then (LZ4) room BagChunkDecoder leaves behind it
    // The message whose bulk went to the sink (its record's offset; none: UINT32_MAX): those bytes
    // are not in `bytes`.
    uint32_t bulk_record = UINT32_MAX, bulk_offset = 0;
    uint8_t* bulk = nullptr;
    std::exception_ptr error;  // a chunk read ahead that turned out damaged: thrown when it is reached
  };
  struct Record;
  class BulkRouter;

  void readIndex();
  void readChunkIndex(uint32_t chunk, const std::map<uint32_t, uint32_t>& ids, uint32_t index_records);
  Record record(uint64_t position, const char* what, bool with_data);
  [[noreturn]] void fail(uint64_t position, const char* what, const std::string& problem) const;
  // Its chunks_[chunk].size bytes, in .bytes (read with the next chunk to be played, if that is not
  // in yet: their LZ4 checksums are checked side by side).
  CachedChunk& chunkData(uint32_t chunk);
  // Reads and decompresses chunk into slot; an LZ4 content checksum may be left in `deferred`.
  void loadChunk(uint32_t chunk, CachedChunk& slot, detail::DeferredChecksum* deferred);
  // The next chunk after `chunk` in play order that is not in the cache (UINT32_MAX: none near).
  uint32_t chunkAhead(uint32_t chunk) const;
  CachedChunk* cached(uint32_t chunk);
  [[noreturn]] void damaged(uint32_t chunk, const std::string& problem) const;
  // Marks `chunk` skipped; the error for it (`what` says what is wrong), with its messages not given.
  BagDamagedChunk skip(uint32_t chunk, const std::string& what);

  std::string path_;
  std::unique_ptr<detail::PreadFile> file_;
  std::unique_ptr<detail::BagChunkDecoder> decoder_;
  std::vector<BagConnection> connections_;
  std::vector<Chunk> chunks_;  // by position
  std::vector<Entry> entries_;  // in play order
  size_t next_ = 0;
  std::array<CachedChunk, 6> cache_;
  uint64_t uses_ = 0;
  ChunkBytes compressed_;
  BagBulkSink* sink_ = nullptr;
};

}  // namespace viper::dataset
