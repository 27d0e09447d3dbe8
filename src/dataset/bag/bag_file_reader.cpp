#include "viper/dataset/bag_file_reader.h"

#include "bag_chunk_decoder.h"
#include "bag_format.h"
#include "pread_file.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string_view>

namespace viper::dataset {

using namespace bag_format;

namespace {

constexpr uint32_t kIndexEntrySize = 12;  // sec, nsec, offset
constexpr uint8_t kOpMessageDefinition = 0x01;  // format 1.2's, skipped in chunks as rosbag does

// LZ4 makes at most 255 bytes of one (a run's length in 255s): a chunk header saying more than that
// is damaged, and is not given the memory it asks for.
constexpr uint64_t kMaxLz4Ratio = 255;

}  // namespace

const std::string& BagConnection::field(const std::string& name) const {
  static const std::string none;
  const auto it = fields.find(name);
  return it == fields.end() ? none : it->second;
}

// A record of the index part of the file: its header's fields (views into the file's window, valid
// until the next read) and where its data is (the data itself where asked for, in the same window).
struct BagFileReader::Record {
  const BagFileReader* reader;
  const char* what;
  uint64_t position;
  std::map<std::string_view, std::string_view> fields;
  const uint8_t* data;
  uint64_t data_position;
  uint32_t data_size;

  uint64_t end() const { return data_position + data_size; }

  template <typename T>
  T number(const char* name) const {
    const auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != sizeof(T))
      reader->fail(position, what, "no " + std::to_string(sizeof(T)) + "-byte field '" + name + "'");
    return load<T>(reinterpret_cast<const uint8_t*>(it->second.data()));
  }
  std::string text(const char* name) const {
    const auto it = fields.find(name);
    if (it == fields.end()) reader->fail(position, what, std::string("no field '") + name + "'");
    return std::string(it->second);
  }
  void expectOp(uint8_t op) const {
    const uint8_t found = number<uint8_t>("op");
    if (found != op) reader->fail(position, what, "op " + std::to_string(found) + ", not " + std::to_string(op));
  }
  void expectVersion1() const {
    const uint32_t version = number<uint32_t>("ver");
    if (version != 1) reader->fail(position, what, "version " + std::to_string(version) + ", not 1");
  }
};

BagFileReader::BagFileReader(const std::string& path)
    : path_(path),
      file_(std::make_unique<detail::PreadFile>(path, "cannot read bag")),
      decoder_(std::make_unique<detail::BagChunkDecoder>()) {
  readIndex();
}

BagFileReader::~BagFileReader() = default;

void BagFileReader::fail(uint64_t position, const char* what, const std::string& problem) const {
  throw std::runtime_error(path_ + ": " + what + " at byte " + std::to_string(position) + ": " + problem +
                           " (`rosbag reindex` rebuilds a damaged or missing index)");
}

BagFileReader::Record BagFileReader::record(uint64_t position, const char* what, bool with_data) {
  if (!file_->holds(position, 8))
    fail(position, what, "past the end of the file (" + std::to_string(file_->size()) + " bytes)");
  const uint32_t header_size = load<uint32_t>(file_->window(position, 4));
  const uint64_t data_position = position + 8 + header_size;
  if (!file_->holds(position, 8 + uint64_t{header_size})) fail(position, what, "its header runs past the end of the file");
  const uint32_t data_size = load<uint32_t>(file_->window(position + 4 + header_size, 4));
  if (!file_->holds(data_position, data_size)) fail(position, what, "its data runs past the end of the file");
  const uint8_t* bytes = file_->window(position, static_cast<size_t>(8 + uint64_t{header_size} + (with_data ? data_size : 0)));
  Record r{this, what, position, {}, with_data ? bytes + 8 + header_size : nullptr, data_position, data_size};
  // A name given twice: the last value, as ros::Header keeps it.
  if (!forEachField(bytes + 4, header_size, [&](std::string_view name, std::string_view value) { r.fields[name] = value; }))
    fail(position, what, "its header is malformed");
  return r;
}

void BagFileReader::readIndex() {
  if (!file_->holds(0, kVersionLength) ||
      std::string_view(reinterpret_cast<const char*>(file_->window(0, kVersionLength)), kVersionLength) != kVersion)
    throw std::runtime_error(path_ + ": not a ROS bag of format 2.0 (its first line is not '#ROSBAG V2.0')");
  const Record header = record(kVersionLength, "file header", false);
  header.expectOp(kOpFileHeader);
  const uint64_t index_position = header.number<uint64_t>("index_pos");
  const uint32_t connection_count = header.number<uint32_t>("conn_count");
  const uint32_t chunk_count = header.number<uint32_t>("chunk_count");
  const auto encryptor = header.fields.find("encryptor");
  if (encryptor != header.fields.end() && !encryptor->second.empty())
    throw std::runtime_error(path_ + ": encrypted (" + std::string(encryptor->second) + "): not supported");
  if (index_position == 0)
    throw std::runtime_error(path_ + ": the bag has no index (a recording that did not finish): `rosbag reindex " +
                             path_ + "` recovers its messages");
  if (index_position > file_->size() || (index_position == file_->size() && connection_count + chunk_count > 0))
    throw std::runtime_error(path_ + ": its index (at byte " + std::to_string(index_position) +
                             ") is past the end of the file (" + std::to_string(file_->size()) +
                             " bytes): the bag was cut short; `rosbag reindex " + path_ + "` recovers its messages");

  // The connections, by id; a connection given twice keeps its first record, as rosbag does.
  std::map<uint32_t, BagConnection> by_id;
  uint64_t at = index_position;
  for (uint32_t i = 0; i < connection_count; ++i) {
    const Record r = record(at, "connection record", true);
    r.expectOp(kOpConnection);
    BagConnection c{r.number<uint32_t>("conn"), r.text("topic"), {}, 0};
    if (!forEachField(r.data, r.data_size, [&](std::string_view name, std::string_view value) {
          c.fields[std::string(name)] = std::string(value);
        }))
      fail(at, "connection record", "its connection header is malformed");
    // rosbag's connection headers have these three always, empty where the record has none.
    for (const char* name : {"type", "md5sum", "message_definition"}) c.fields.emplace(name, "");
    by_id.emplace(c.id, std::move(c));
    at = r.end();
  }
  std::map<uint32_t, uint32_t> ids;  // connection id -> its index in connections_
  for (auto& [id, c] : by_id) {
    ids[id] = static_cast<uint32_t>(connections_.size());
    connections_.push_back(std::move(c));
  }

  struct Info {
    uint64_t position;
    uint32_t index_records;  // one a connection with messages in the chunk
  };
  std::vector<Info> infos;
  for (uint32_t i = 0; i < chunk_count; ++i) {
    const Record r = record(at, "chunk info record", false);
    r.expectOp(kOpChunkInfo);
    r.expectVersion1();
    infos.push_back({r.number<uint64_t>("chunk_pos"), r.number<uint32_t>("count")});
    at = r.end();
  }
  std::stable_sort(infos.begin(), infos.end(), [](const Info& a, const Info& b) { return a.position < b.position; });
  for (const Info& info : infos) {
    const Record r = record(info.position, "chunk record", false);
    r.expectOp(kOpChunk);
    const std::string compression = r.text("compression");
    if (compression != "none" && compression != "lz4" && compression != "bz2")
      fail(info.position, "chunk record", "compression '" + compression + "' (not none, lz4 or bz2)");
    chunks_.push_back({info.position, r.data_position, r.data_size, r.number<uint32_t>("size"),
                       bagCompressionFromName(compression)});
    readChunkIndex(static_cast<uint32_t>(chunks_.size() - 1), ids, info.index_records);
  }
  // Play order: by time, then file order (rosbag's order for one connection's equal times).
  std::stable_sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
    if (a.sec != b.sec) return a.sec < b.sec;
    if (a.nsec != b.nsec) return a.nsec < b.nsec;
    return a.chunk != b.chunk ? a.chunk < b.chunk : a.offset < b.offset;
  });
}

// The index data records after a chunk: per connection, the time and offset of its messages there.
void BagFileReader::readChunkIndex(uint32_t chunk, const std::map<uint32_t, uint32_t>& ids, uint32_t index_records) {
  uint64_t at = chunks_[chunk].data_position + chunks_[chunk].data_size;
  for (uint32_t k = 0; k < index_records; ++k) {
    const Record r = record(at, "index record", true);
    r.expectOp(kOpIndexData);
    r.expectVersion1();
    const uint32_t count = r.number<uint32_t>("count");
    if (count > r.data_size / kIndexEntrySize)
      fail(at, "index record", std::to_string(count) + " entries in " + std::to_string(r.data_size) + " bytes");
    // Entries of a connection the index does not list are not played (rosbag::View plays only listed ones).
    const auto known = ids.find(r.number<uint32_t>("conn"));
    for (uint32_t j = 0; j < count && known != ids.end(); ++j) {
      const uint8_t* e = r.data + j * kIndexEntrySize;
      // As ros::Time holds it: nanoseconds below a second.
      const uint64_t sec = load<uint32_t>(e) + uint64_t{load<uint32_t>(e + 4)} / 1000000000u;
      const uint32_t nsec = load<uint32_t>(e + 4) % 1000000000u;
      // rosbag loads no message at time 0 (before ros::TIME_MIN) nor past ros::TIME_MAX.
      if ((sec == 0 && nsec == 0) || sec > UINT32_MAX) continue;
      entries_.push_back({static_cast<uint32_t>(sec), nsec, chunk, load<uint32_t>(e + 8), known->second});
      Chunk& c = chunks_[chunk];
      if (c.last_connection == UINT32_MAX || load<uint32_t>(e + 8) >= c.last_entry)
        c.last_entry = load<uint32_t>(e + 8), c.last_connection = known->second;
      ++connections_[known->second].messages;
    }
    at = r.end();
  }
}

void BagFileReader::select(const std::function<bool(const BagConnection&)>& wanted) {
  if (next_ != 0) throw std::logic_error("BagFileReader::select after next()");
  std::vector<char> keep(connections_.size());
  for (size_t i = 0; i < connections_.size(); ++i) keep[i] = wanted(connections_[i]);
  entries_.erase(std::remove_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return !keep[e.connection]; }),
                 entries_.end());
  // A chunk's last message not selected: not offered to the sink, it is never given.
  for (Chunk& c : chunks_)
    if (c.last_connection != UINT32_MAX && !keep[c.last_connection]) c.last_connection = UINT32_MAX;
}

void BagFileReader::damaged(uint32_t chunk, const std::string& problem) const {
  throw BagDamagedChunk(path_ + ": damaged chunk at byte " + std::to_string(chunks_[chunk].position) + ": " + problem,
                        chunks_[chunk].position, {});
}

BagDamagedChunk BagFileReader::skip(uint32_t chunk, const std::string& what) {
  chunks_[chunk].skipped = true;
  for (CachedChunk& c : cache_)
    if (c.chunk == chunk) c.used = 0, c.error = nullptr;
  std::vector<BagIndexedMessage> skipped;
  for (size_t i = next_; i < entries_.size(); ++i)
    if (entries_[i].chunk == chunk)
      skipped.push_back({&connections_[entries_[i].connection], entries_[i].sec, entries_[i].nsec});
  const std::string count = std::to_string(skipped.size()) + (skipped.size() == 1 ? " message" : " messages");
  return BagDamagedChunk(what + " (" + count + " skipped)", chunks_[chunk].position, std::move(skipped));
}

namespace {

// A record in a chunk's first `decoded` bytes (of `size`) at `at`.
struct ChunkRecord {
  enum Status { kOk, kIncomplete, kBad } status = kBad;
  std::string problem;  // kBad: what is wrong
  int op = -1;
  uint64_t data_at = 0;
  uint32_t data_size = 0;
};

ChunkRecord chunkRecord(const uint8_t* bytes, uint64_t decoded, uint64_t size, uint64_t at) {
  ChunkRecord r;
  const auto where = [&] { return "the record at offset " + std::to_string(at) + " of " + std::to_string(size); };
  if (size < 8 || at > size - 8) return r.problem = where() + " runs past the chunk's end", r;
  if (at + 4 > decoded) return r.status = ChunkRecord::kIncomplete, r;
  const uint32_t header_size = load<uint32_t>(bytes + at);
  if (header_size > size - 8 - at) return r.problem = where() + ": its header runs past the chunk's end", r;
  if (at + 8 + header_size > decoded) return r.status = ChunkRecord::kIncomplete, r;
  r.data_at = at + 8 + header_size;
  r.data_size = load<uint32_t>(bytes + at + 4 + header_size);
  if (r.data_size > size - r.data_at) return r.problem = where() + ": its data runs past the chunk's end", r;
  if (!forEachField(bytes + at + 4, header_size, [&](std::string_view name, std::string_view value) {
        if (name == "op" && value.size() == 1) r.op = static_cast<uint8_t>(value[0]);
      }))
    return r.problem = where() + ": its header is malformed", r;
  if (r.op != kOpConnection && r.op != kOpMessageDefinition && r.op != kOpMessageData)
    return r.problem = where() + " is no message (op " + std::to_string(r.op) + ")", r;
  r.status = ChunkRecord::kOk;
  return r;
}

}  // namespace

// Routes the bulk of a chunk's last message to the sink, once its record is decoded and the sink
// takes it; connection records before it are skipped, as next() skips them.
class BagFileReader::BulkRouter : public detail::ChunkRouter {
 public:
  BulkRouter(BagBulkSink& sink, const BagConnection& connection, const Chunk& chunk, CachedChunk& slot)
      : sink_(sink), connection_(connection), chunk_(chunk), slot_(slot), at_(chunk.last_entry) {}

  Answer route(const uint8_t* bytes, size_t decoded, size_t& begin, size_t& end, uint8_t*& to) override {
    for (;;) {
      const ChunkRecord r = chunkRecord(bytes, decoded, chunk_.size, at_);
      if (r.status == ChunkRecord::kIncomplete) return kNotYet;
      if (r.status == ChunkRecord::kBad) return kNever;  // next() names it
      if (r.op != kOpMessageData) {
        at_ = r.data_at + r.data_size;
        continue;
      }
      if (r.data_size < BagBulkSink::kMinBulk) return kNever;
      const uint32_t available = static_cast<uint32_t>(std::min<uint64_t>(decoded - std::min<uint64_t>(decoded, r.data_at), r.data_size));
      uint32_t offset = 0;
      to = sink_.bulk(connection_, bytes + r.data_at, available, r.data_size, offset);
      if (!to) return kNotYet;
      if (offset > available) return kNever;  // a sink that breaks its promise gets nothing
      begin = r.data_at + offset, end = r.data_at + r.data_size;
      slot_.bulk_record = chunk_.last_entry, slot_.bulk_offset = offset, slot_.bulk = to;
      return kRouted;
    }
  }

 private:
  BagBulkSink& sink_;
  const BagConnection& connection_;
  const Chunk& chunk_;
  CachedChunk& slot_;
  uint64_t at_;
};

BagFileReader::CachedChunk* BagFileReader::cached(uint32_t chunk) {
  for (CachedChunk& c : cache_)
    if (c.used != 0 && c.chunk == chunk) return &c;
  return nullptr;
}

uint32_t BagFileReader::chunkAhead(uint32_t chunk) const {
  constexpr size_t kLookAhead = 64;  // entries: a frame's messages
  for (size_t i = next_; i < entries_.size() && i < next_ + kLookAhead; ++i) {
    const uint32_t c = entries_[i].chunk;
    if (c == chunk || chunks_[c].skipped) continue;
    for (const CachedChunk& s : cache_)
      if (s.used != 0 && s.chunk == c) return UINT32_MAX;  // in already: its own turn comes later
    return chunks_[c].compression == BagCompression::kLz4 ? c : UINT32_MAX;
  }
  return UINT32_MAX;
}

void BagFileReader::loadChunk(uint32_t chunk, CachedChunk& slot, detail::DeferredChecksum* deferred) {
  slot.used = 0;  // holds nothing until the chunk is in
  slot.bulk_record = UINT32_MAX, slot.bulk = nullptr;
  slot.error = nullptr;
  const Chunk& c = chunks_[chunk];
  if (c.compression == BagCompression::kNone) {
    if (c.data_size != c.size)
      damaged(chunk, "holds " + std::to_string(c.data_size) + " bytes, its header says " + std::to_string(c.size));
    slot.bytes.resize(c.size);
    file_->read(c.data_position, slot.bytes.data(), c.size);
  } else {
    if (c.compression == BagCompression::kLz4 && c.size > kMaxLz4Ratio * c.data_size + 64)
      damaged(chunk, "its header says " + std::to_string(c.size) + " bytes, more than LZ4 makes of " +
                         std::to_string(c.data_size));
    compressed_.resize(c.data_size);
    file_->read(c.data_position, compressed_.data(), c.data_size);
    std::optional<BulkRouter> router;
    if (sink_ && c.last_connection != UINT32_MAX && c.compression == BagCompression::kLz4)
      router.emplace(*sink_, connections_[c.last_connection], c, slot);
    const std::string problem = decoder_->decode(c.compression, compressed_.data(), c.data_size, slot.bytes, c.size,
                                                 router ? &*router : nullptr, deferred);
    if (!problem.empty()) damaged(chunk, problem);
  }
  slot.chunk = chunk;
  slot.used = ++uses_;
}

BagFileReader::CachedChunk& BagFileReader::chunkData(uint32_t chunk) {
  if (CachedChunk* c = cached(chunk)) {
    if (c->error) std::rethrow_exception(c->error);
    c->used = ++uses_;
    return *c;
  }
  const uint32_t ahead = chunkAhead(chunk);
  const int count = ahead == UINT32_MAX ? 1 : 2;
  const uint32_t batch[2] = {chunk, ahead};
  CachedChunk* slots[2] = {nullptr, nullptr};
  detail::DeferredChecksum sums[2];
  for (int i = 0; i < count; ++i) {
    // The least recently used slot, not this batch's other one.
    CachedChunk* slot = nullptr;
    for (CachedChunk& c : cache_)
      if (&c != slots[0] && (!slot || c.used < slot->used)) slot = &c;
    slots[i] = slot;
    if (i == 0) {
      loadChunk(batch[i], *slot, &sums[i]);  // throws for the chunk asked for
      continue;
    }
    try {
      loadChunk(batch[i], *slot, &sums[i]);
    } catch (const std::runtime_error&) {  // the chunk ahead: named once it is reached
      sums[i].pending = false;
      slot->error = std::current_exception(), slot->chunk = batch[i], slot->used = ++uses_;
    }
  }
  std::vector<const std::vector<detail::BytePiece>*> streams;
  std::vector<int> of;
  for (int i = 0; i < count; ++i)
    if (sums[i].pending) streams.push_back(&sums[i].pieces), of.push_back(i);
  std::vector<uint32_t> hashes(streams.size());
  detail::xxh32Streams(streams, hashes.data());
  // Every verdict is kept before the chunk asked for may throw: reading goes on after it.
  for (size_t k = 0; k < streams.size(); ++k) {
    const int i = of[k];
    if (hashes[k] == sums[i].expected) continue;
    try {
      damaged(batch[i], detail::kLz4ChecksumProblem);
    } catch (const BagDamagedChunk&) {
      slots[i]->error = std::current_exception();
    }
  }
  if (slots[0]->error) {
    const std::exception_ptr error = slots[0]->error;
    slots[0]->used = 0, slots[0]->error = nullptr;
    std::rethrow_exception(error);
  }
  return *slots[0];
}

bool BagFileReader::next(BagMessage& message) {
  while (next_ < entries_.size() && chunks_[entries_[next_].chunk].skipped) ++next_;
  if (next_ == entries_.size()) return false;
  const Entry& e = entries_[next_];
  CachedChunk* found = nullptr;
  ChunkRecord r;
  try {
    found = &chunkData(e.chunk);
    const uint64_t size = chunks_[e.chunk].size;
    // The record at the entry's offset; connection records before it are skipped (rosbag's writer
    // indexes a connection's first message at its connection record).
    for (uint64_t at = e.offset;; at = r.data_at + r.data_size) {
      r = chunkRecord(found->bytes.data(), size, size, at);
      if (r.status != ChunkRecord::kOk) damaged(e.chunk, r.problem);
      if (r.op == kOpMessageData) break;
    }
  } catch (const BagDamagedChunk& d) {
    throw skip(e.chunk, d.what());
  }
  CachedChunk& slot = *found;
  message = {&connections_[e.connection], e.sec, e.nsec, slot.bytes.data() + r.data_at, r.data_size};
  if (slot.bulk_record == e.offset) {
    // Its bulk is the sink's now, and the chunk's copy has a hole: decoded again if asked again.
    message.bulk = slot.bulk, message.bulk_offset = slot.bulk_offset;
    slot.used = 0;
  }
  ++next_;
  return true;
}

}  // namespace viper::dataset
