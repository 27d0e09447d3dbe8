#include "viper/dataset/bag_file_writer.h"

#include "bag_format.h"
#include "direct_file.h"

#include <bzlib.h>
#include <lz4.h>
#include <lz4frame.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace viper::dataset {

namespace {

using namespace bag_format;

template <typename T, typename Bytes>
void append(Bytes& out, T value) {  // little endian, as the format wants (x86 and ARM)
  const size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

template <typename Bytes>
void appendBytes(Bytes& out, const void* bytes, size_t size) {
  out.insert(out.end(), static_cast<const uint8_t*>(bytes), static_cast<const uint8_t*>(bytes) + size);
}

// A record header: fields "name=value", each after its 4-byte length.
class Header {
 public:
  template <typename T>
  Header& field(const char* name, T value) {
    std::string bytes(sizeof(T), '\0');
    std::memcpy(bytes.data(), &value, sizeof(T));
    return text(name, bytes);
  }
  Header& text(const std::string& name, const std::string& value) {
    append<uint32_t>(bytes_, static_cast<uint32_t>(name.size() + 1 + value.size()));
    appendBytes(bytes_, name.data(), name.size());
    bytes_.push_back('=');
    appendBytes(bytes_, value.data(), value.size());
    return *this;
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<uint8_t> bytes_;
};

// A record: header length, header, data length (data follows, written by the caller).
template <typename Bytes>
void appendRecordStart(Bytes& out, const Header& header, uint32_t data_size) {
  append<uint32_t>(out, static_cast<uint32_t>(header.bytes().size()));
  appendBytes(out, header.bytes().data(), header.bytes().size());
  append<uint32_t>(out, data_size);
}

// Compressibility from three 16 KiB samples (a quarter, half and three quarters in): LZ4 on all of
// a 16 MB float flow image costs ~25 ms of CPU to save a quarter of its bytes.
template <typename Bytes>
double sampledRatio(const Bytes& chunk) {
  constexpr int kSample = 16 * 1024;
  if (chunk.size() < 4 * static_cast<size_t>(kSample)) return 1e9;  // small: compress it
  static thread_local std::vector<char> out(LZ4_compressBound(kSample));
  size_t in = 0, compressed = 0;
  for (int q = 1; q <= 3; ++q) {
    const char* at = reinterpret_cast<const char*>(chunk.data()) + chunk.size() * q / 4;
    compressed += static_cast<size_t>(LZ4_compress_default(at, out.data(), kSample, static_cast<int>(out.size())));
    in += kSample;
  }
  return compressed ? static_cast<double>(in) / static_cast<double>(compressed) : 1e9;
}

}  // namespace

BagCompression bagCompressionFromName(const std::string& name) {
  if (name == "none") return BagCompression::kNone;
  if (name == "lz4") return BagCompression::kLz4;
  if (name == "bz2") return BagCompression::kBz2;
  throw std::invalid_argument("bag compression '" + name + "': none, lz4 or bz2");
}

BagFileWriter::BagFileWriter(const std::string& path, const BagFileOptions& options)
    : path_(path), options_(options), file_(std::make_unique<detail::DirectFile>(path, "cannot write bag")) {
  put(kVersion, kVersionLength);
  // The file header record (two lengths and 4096 bytes of header and padding), written again with
  // the index's position on close().
  const std::vector<uint8_t> header(kFileHeaderLength + 8, ' ');
  put(header.data(), header.size());
}

BagFileWriter::~BagFileWriter() {
  try {
    close();
  } catch (const std::exception&) {
  }
}

uint32_t BagFileWriter::addConnection(const std::string& topic, const std::map<std::string, std::string>& fields) {
  connections_.push_back({topic, fields, false});
  return static_cast<uint32_t>(connections_.size() - 1);
}

template <typename Bytes>
void BagFileWriter::writeConnectionRecord(Bytes& out, uint32_t id) const {
  const Connection& c = connections_.at(id);
  Header data;
  for (const auto& [name, value] : c.fields) data.text(name, value);
  Header header;
  header.field("op", kOpConnection).field("conn", id).text("topic", c.topic);
  appendRecordStart(out, header, static_cast<uint32_t>(data.bytes().size()));
  appendBytes(out, data.bytes().data(), data.bytes().size());
}

uint8_t* BagFileWriter::beginMessage(uint32_t connection, uint32_t sec, uint32_t nsec, uint32_t size,
                                     uint32_t bulk_offset) {
  if (closed_) throw std::logic_error(path_ + ": message written after close()");
  if (connection >= connections_.size()) throw std::invalid_argument(path_ + ": no connection " + std::to_string(connection));
  if (sec == 0 && nsec == 0) throw std::invalid_argument(path_ + ": a message at time 0 (rosbag reads none before 0.000000001)");
  finishMessage();
  if (chunk_.empty()) {
    chunk_index_.clear();
    current_ = ChunkInfo{file_->size(), sec, nsec, sec, nsec, {}};
  }
  Connection& c = connections_[connection];
  if (!c.in_bag) {  // the first message of a connection: its record goes before it (rosbag does so)
    writeConnectionRecord(chunk_, connection);
    c.in_bag = true;
  }
  const uint64_t t = packTime(sec, nsec);
  if (sec < current_.start_sec || (sec == current_.start_sec && nsec < current_.start_nsec))
    current_.start_sec = sec, current_.start_nsec = nsec;
  if (sec > current_.end_sec || (sec == current_.end_sec && nsec > current_.end_nsec))
    current_.end_sec = sec, current_.end_nsec = nsec;
  chunk_index_[connection].push_back({sec, nsec, static_cast<uint32_t>(chunk_.size())});
  Header header;
  header.field("op", kOpMessageData).field("conn", connection).field("time", t);
  appendRecordStart(chunk_, header, size);
  const size_t at = chunk_.size();
  chunk_.resize(at + size);  // filled by the caller (not zeroed first: ChunkBytes)
  if (bulk_offset > 0 && bulk_offset < size && size - bulk_offset >= kMinBulkBytes) block_starts_.push_back(at + bulk_offset);
  message_open_ = true;
  return chunk_.data() + at;
}

void BagFileWriter::finishMessage() {
  if (!message_open_) return;
  message_open_ = false;
  if (chunk_.size() > options_.chunk_threshold) closeChunk();
}

namespace {

// An LZ4 frame as roslz4 reads it: independent blocks of at most 4 MB, no block checksums, no
// content size, the content checksum at the end.
LZ4F_preferences_t roslz4Preferences() {
  LZ4F_preferences_t prefs;
  std::memset(&prefs, 0, sizeof(prefs));
  prefs.frameInfo.blockSizeID = LZ4F_max4MB;
  prefs.frameInfo.blockMode = LZ4F_blockIndependent;
  prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  return prefs;
}

}  // namespace

size_t BagFileWriter::compressLz4Frame() {
  const LZ4F_preferences_t prefs = roslz4Preferences();
  compressed_.resize(LZ4F_compressFrameBound(chunk_.size(), &prefs));
  const size_t n = LZ4F_compressFrame(compressed_.data(), compressed_.size(), chunk_.data(), chunk_.size(), &prefs);
  if (LZ4F_isError(n)) throw std::runtime_error(path_ + ": cannot write bag: LZ4: " + LZ4F_getErrorName(n));
  return n;
}

// The same frame with a block ending where each bulk starts: the chunk in pieces, each flushed.
size_t BagFileWriter::compressLz4Blocks() {
  LZ4F_preferences_t prefs = roslz4Preferences();
  prefs.autoFlush = 1;
  std::vector<size_t> cuts = block_starts_;
  cuts.push_back(chunk_.size());
  size_t bound = LZ4F_HEADER_SIZE_MAX, from = 0;
  for (size_t cut : cuts) bound += LZ4F_compressBound(cut - from, &prefs), from = cut;
  compressed_.resize(bound);
  if (!lz4_) {
    LZ4F_cctx* made = nullptr;
    if (LZ4F_isError(LZ4F_createCompressionContext(&made, LZ4F_VERSION))) throw std::bad_alloc();
    lz4_ = {made, LZ4F_freeCompressionContext};
  }
  LZ4F_cctx* const cctx = lz4_.get();
  auto check = [&](size_t rc) {
    if (LZ4F_isError(rc)) throw std::runtime_error(path_ + ": cannot write bag: LZ4: " + LZ4F_getErrorName(rc));
    return rc;
  };
  size_t n = check(LZ4F_compressBegin(cctx, compressed_.data(), compressed_.size(), &prefs));
  from = 0;
  for (size_t cut : cuts) {
    n += check(LZ4F_compressUpdate(cctx, compressed_.data() + n, compressed_.size() - n, chunk_.data() + from,
                                   cut - from, nullptr));
    from = cut;
  }
  return n + check(LZ4F_compressEnd(cctx, compressed_.data() + n, compressed_.size() - n, nullptr));
}

void BagFileWriter::closeChunk() {
  if (chunk_.empty()) return;
  // The chunk's data: compressed if it pays, else as it is.
  const uint8_t* data = chunk_.data();
  size_t data_size = chunk_.size();
  std::string compression = "none";
  if (options_.compression == BagCompression::kLz4 &&
      (options_.min_ratio <= 1.0 || sampledRatio(chunk_) >= options_.min_ratio)) {
    const size_t n = block_starts_.empty() ? compressLz4Frame() : compressLz4Blocks();
    data = compressed_.data(), data_size = n, compression = "lz4";
  } else if (options_.compression == BagCompression::kBz2) {
    unsigned int n = static_cast<unsigned int>(chunk_.size() + chunk_.size() / 100 + 600);
    compressed_.resize(n);
    const int rc = BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(compressed_.data()), &n,
                                            reinterpret_cast<char*>(chunk_.data()),
                                            static_cast<unsigned int>(chunk_.size()), 9, 0, 30);
    if (rc != BZ_OK) throw std::runtime_error(path_ + ": cannot write bag: bzip2 error " + std::to_string(rc));
    data = compressed_.data(), data_size = n, compression = "bz2";
  }
  std::vector<uint8_t> record;
  Header header;
  header.field("op", kOpChunk).text("compression", compression).field("size", static_cast<uint32_t>(chunk_.size()));
  appendRecordStart(record, header, static_cast<uint32_t>(data_size));
  put(record.data(), record.size());
  put(data, data_size);
  // Then the chunk's index: per connection, the time and offset of each of its messages.
  record.clear();
  for (const auto& [conn, entries] : chunk_index_) {
    Header index;
    index.field("op", kOpIndexData).field("ver", uint32_t{1}).field("conn", conn).field("count",
                                                                                      static_cast<uint32_t>(entries.size()));
    appendRecordStart(record, index, static_cast<uint32_t>(entries.size() * 12));
    for (const IndexEntry& e : entries) {
      append<uint32_t>(record, e.sec);
      append<uint32_t>(record, e.nsec);
      append<uint32_t>(record, e.offset);
    }
  }
  put(record.data(), record.size());
  for (const auto& [conn, entries] : chunk_index_) current_.counts[conn] = static_cast<uint32_t>(entries.size());
  chunk_infos_.push_back(current_);
  chunk_.clear();
  block_starts_.clear();
}

void BagFileWriter::close() {
  if (closed_) return;
  closed_ = true;
  finishMessage();
  closeChunk();
  // The index: every connection, then every chunk's info; then the file header pointing at it.
  const uint64_t index_position = file_->size();
  std::vector<uint8_t> index;
  for (uint32_t id = 0; id < connections_.size(); ++id)
    if (connections_[id].in_bag) writeConnectionRecord(index, id);
  for (const ChunkInfo& c : chunk_infos_) {
    Header header;
    header.field("op", kOpChunkInfo)
        .field("ver", uint32_t{1})
        .field("chunk_pos", c.position)
        .field("start_time", packTime(c.start_sec, c.start_nsec))
        .field("end_time", packTime(c.end_sec, c.end_nsec))
        .field("count", static_cast<uint32_t>(c.counts.size()));
    appendRecordStart(index, header, static_cast<uint32_t>(c.counts.size() * 8));
    for (const auto& [conn, n] : c.counts) {
      append<uint32_t>(index, conn);
      append<uint32_t>(index, n);
    }
  }
  put(index.data(), index.size());
  const uint32_t connection_count = static_cast<uint32_t>(
      std::count_if(connections_.begin(), connections_.end(), [](const Connection& c) { return c.in_bag; }));
  Header header;
  header.field("op", kOpFileHeader)
      .field("index_pos", index_position)
      .field("conn_count", connection_count)
      .field("chunk_count", static_cast<uint32_t>(chunk_infos_.size()));
  std::vector<uint8_t> record;
  appendRecordStart(record, header, kFileHeaderLength - static_cast<uint32_t>(header.bytes().size()));
  record.resize(record.size() + kFileHeaderLength - header.bytes().size(), ' ');
  file_->finish(kVersionLength, record.data(), record.size());
}

void BagFileWriter::put(const void* bytes, size_t size) { file_->append(bytes, size); }

}  // namespace viper::dataset
