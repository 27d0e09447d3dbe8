// The package's own bag readers on damaged bags, against rosbag: a bag without its index names
// `rosbag reindex`; a damaged chunk (with a bulk sink or without, an LZ4 chunk that decodes to other
// bytes, two chunks checked side by side, an index offset past its chunk) names its byte offset after
// every message before it came back, and reading goes on after it; damage anywhere never crashes the
// reader. viper::BagReader's errors name the file; a damaged chunk of other topics is not read, one
// of the topics asked for is an error once, then reading goes on. Intact bags: test_bag_reader.cpp.
#include "bag_reader_test_support.h"

#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace {

using viper::dataset::BagFileReader;
using viper::test::readFile;
using viper::test::tempDir;

// BagFileReader's messages of the connections `wanted` selects (nullptr: all), reading on after
// each damaged chunk; `errors` gets each (nullptr: fail the test; their skipped messages'
// connections are gone with the reader). Another error ends the reading.
std::vector<Read> readOnWithReader(const std::string& path, std::vector<viper::dataset::BagDamagedChunk>* errors,
                                   const std::function<bool(const viper::dataset::BagConnection&)>* wanted = nullptr) {
  std::vector<Read> out;
  try {
    BagFileReader bag(path);
    if (wanted) bag.select(*wanted);
    viper::dataset::BagMessage m;
    for (size_t damaged = 0; damaged <= 1000;) {
      try {
        if (!bag.next(m)) break;
        out.push_back(readOf(m));
      } catch (const viper::dataset::BagDamagedChunk& e) {
        if (errors == nullptr) ADD_FAILURE() << e.what();
        else errors->push_back(e);
        EXPECT_FALSE(e.skipped().empty()) << e.what();
        if (++damaged > 1000) ADD_FAILURE() << "read on after 1000 damaged chunks";
      }
    }
  } catch (const std::runtime_error&) {  // the index, or the file: nothing to read on after
  }
  return out;
}

// A damaged chunk whose bulk went to the sink is named as any other, after every message before it.
TEST(BagFileReader, ADamagedChunkWithASinkIsNamedAfterTheMessagesBeforeIt) {
  const std::string dir = tempDir("viper_bag_reader_"), intact = dir + "/intact.bag", damaged = dir + "/damaged.bag";
  writeLargeImages(intact, Writer::kViperBulk);
  std::string bytes = readFile(intact);
  size_t field = 0;
  for (int k = 0; k < 3; ++k) field = bytes.find("compression=lz4", field + 1);
  ASSERT_NE(field, std::string::npos);
  // BagFileWriter's chunk header: its length, then op (4 + 4 bytes), then the compression field's
  // length and text.
  const size_t chunk = field - 16;
  ASSERT_EQ(bytes.substr(chunk + 8, 4), std::string("op=\x05", 4));
  uint32_t header_size, data_size;
  std::memcpy(&header_size, bytes.data() + chunk, 4);
  std::memcpy(&data_size, bytes.data() + chunk + 4 + header_size, 4);
  const size_t data_at = chunk + 8 + header_size;
  for (size_t i = data_at + data_size - 2000; i < data_at + data_size - 1990; ++i) bytes[i] = static_cast<char>(~bytes[i]);
  writeFile(damaged, bytes);
  TestSink sink(1.0), intact_sink(1.0);
  std::string error;
  const std::vector<Read> got = readWithReader(damaged, &error, &sink), all = readWithReader(intact, nullptr, &intact_sink);
  EXPECT_NE(error.find(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": "), std::string::npos) << error;
  ASSERT_GT(got.size(), 0u);
  ASSERT_LT(got.size(), all.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i] == all[i]) << "message " << i;
}

std::string withIndexPosition(std::string bytes, uint64_t* index_position) {
  const size_t at = bytes.find("index_pos=");
  EXPECT_NE(at, std::string::npos);
  std::memcpy(index_position, bytes.data() + at + 10, 8);
  std::memset(bytes.data() + at + 10, 0, 8);
  return bytes;
}

// What a recorder that did not finish leaves: its chunks, and the file header's index position
// still 0 (rosbag writes it on close); and a bag cut short before its index.
TEST(BagFileReader, ABagWithoutIndexNamesRosbagReindex) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeWithRosbag(dir + "/whole.bag", rosbag::compression::LZ4);
  uint64_t index_position = 0;
  const std::string unfinished = withIndexPosition(readFile(dir + "/whole.bag"), &index_position);
  ASSERT_GT(index_position, 0u);
  writeFile(dir + "/unfinished.bag", unfinished.substr(0, index_position));
  writeFile(dir + "/cut.bag", readFile(dir + "/whole.bag").substr(0, index_position));
  EXPECT_THROW(rosbag::Bag(dir + "/unfinished.bag", rosbag::bagmode::Read), rosbag::BagUnindexedException);
  for (const char* name : {"/unfinished.bag", "/cut.bag"}) {
    const std::string path = dir + name;
    try {
      BagFileReader bag(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_NE(what.find("`rosbag reindex"), std::string::npos) << what;
      std::cout << what << "\n";
    }
  }
}

// 30 texts of 1500 bytes on one topic, times rising, in 4 KB chunks.
void writeTextBag(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag;
  openWith4KbChunks(bag, path, compression);
  std::mt19937 random(11);
  for (uint32_t i = 0; i < 30; ++i) {
    std_msgs::String s;
    s.data = text(1500, random);
    bag.write("/text", ros::Time(5, i * 1000u), s);
  }
}

// A copy of `intact` at `damaged` with 16 bytes of its n-th chunk's data (from 1) inverted (chunks
// written by rosbag, compressed with `compression`); returns the chunk's offset (npos: no n-th chunk).
size_t damageChunk(const std::string& intact, const std::string& compression, const std::string& damaged, int n) {
  std::string bytes = readFile(intact);
  // rosbag writes a chunk's header fields by name: compression first, after the record's and the
  // field's lengths.
  size_t field = 0;
  for (int k = 0; k < n && field != std::string::npos; ++k) field = bytes.find("compression=" + compression, field + 1);
  if (field == std::string::npos) return field;
  const size_t chunk = field - 8;
  uint32_t header_size;
  std::memcpy(&header_size, bytes.data() + chunk, 4);
  for (size_t i = chunk + 8 + header_size + 40; i < chunk + 8 + header_size + 56; ++i) bytes[i] = static_cast<char>(~bytes[i]);
  writeFile(damaged, bytes);
  return chunk;
}

size_t damageThirdChunk(const std::string& intact, const std::string& compression, const std::string& damaged) {
  return damageChunk(intact, compression, damaged, 3);
}

// Twelve texts of 5000 bytes, one a chunk (rosbag's writer, 4 KB chunks): /a at times 1, 3, .., 11
// (chunks 1, 3, ..), /b at 2, 4, .., 12.
void writeOneMessageChunks(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag;
  openWith4KbChunks(bag, path, compression);
  std::mt19937 random(13);
  for (uint32_t t = 1; t <= 12; ++t) {
    std_msgs::String s;
    s.data = text(5000, random);
    bag.write(t % 2 ? "/a" : "/b", ros::Time(t, 0), s);
  }
  bag.close();
}

// For each compression that can be damaged (lz4, bz2): the bag `write` writes with its n-th chunk
// damaged, checked by check(its path, the chunk's offset, the intact bag's messages by rosbag).
void withDamagedChunk(void (*write)(const std::string&, rosbag::compression::CompressionType), int n,
                      const std::function<void(const std::string&, size_t, const std::vector<Read>&)>& check) {
  const std::string dir = tempDir("viper_bag_reader_");
  for (const auto& [name, compression] : {std::pair{"lz4", rosbag::compression::LZ4},
                                          std::pair{"bz2", rosbag::compression::BZ2}}) {
    SCOPED_TRACE(name);
    const std::string intact = dir + "/intact_" + name + ".bag", damaged = dir + "/damaged_" + name + ".bag";
    write(intact, compression);
    const size_t chunk = damageChunk(intact, name, damaged, n);
    ASSERT_NE(chunk, std::string::npos);
    check(damaged, chunk, readWithRosbag(intact));
  }
}

// A chunk's data with 16 bytes inverted (the third chunk of a bag of one topic, times rising): the
// error names the chunk's offset, after the messages of the chunks before it, as many as rosbag gives.
TEST(BagFileReader, ADamagedChunkIsNamedAfterTheMessagesBeforeIt) {
  withDamagedChunk(writeTextBag, 3, [](const std::string& damaged, size_t chunk, const std::vector<Read>& all) {
    std::string error, rosbag_error;
    const std::vector<Read> got = readWithReader(damaged, &error);
    const std::vector<Read> before = readWithRosbag(damaged, &rosbag_error);
    EXPECT_NE(error.find(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": "), std::string::npos) << error;
    EXPECT_FALSE(rosbag_error.empty()) << "rosbag read the damaged chunk";
    EXPECT_GT(got.size(), 0u);
    EXPECT_EQ(got.size(), before.size()) << "as many messages as rosbag gives before the damage";
    ASSERT_LT(got.size(), all.size());
    for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i] == all[i]) << "message " << i;
    std::cout << got.size() << " of " << all.size() << " messages, then: " << error << "\n";
  });
}

// An LZ4 chunk that still decodes, to other bytes: its last literal changed (the last 5 bytes of an
// LZ4 block are literals; the frame ends with an end mark and the content checksum, 4 bytes each),
// or its stored checksum changed. Only the content checksum tells: the chunk is named as damaged.
TEST(BagFileReader, AnLz4ChunkThatDecodesToOtherBytesFailsItsChecksum) {
  const std::string dir = tempDir("viper_bag_reader_"), intact = dir + "/intact.bag";
  writeTextBag(intact, rosbag::compression::LZ4);
  const std::string whole = readFile(intact);
  size_t field = 0;
  for (int k = 0; k < 3; ++k) field = whole.find("compression=lz4", field + 1);
  ASSERT_NE(field, std::string::npos);
  const size_t chunk = field - 8;
  uint32_t header_size, data_size;
  std::memcpy(&header_size, whole.data() + chunk, 4);
  std::memcpy(&data_size, whole.data() + chunk + 4 + header_size, 4);
  const size_t data_end = chunk + 8 + header_size + data_size;
  const std::vector<Read> all = readWithRosbag(intact);
  for (const auto& [what, at] : {std::pair{"last literal", data_end - 9}, std::pair{"stored checksum", data_end - 1}}) {
    SCOPED_TRACE(what);
    std::string bytes = whole;
    bytes[at] = static_cast<char>(bytes[at] ^ 0x20);
    const std::string damaged = dir + "/damaged.bag";
    writeFile(damaged, bytes);
    std::string error;
    const std::vector<Read> got = readWithReader(damaged, &error);
    EXPECT_NE(error.find(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": LZ4: " +
                         "ERROR_contentChecksum_invalid"), std::string::npos) << error;
    ASSERT_GT(got.size(), 0u);
    ASSERT_LT(got.size(), all.size());
    for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i] == all[i]) << "message " << i;
    // Read on: the chunk's messages skipped, every other one as in the intact bag.
    std::vector<viper::dataset::BagDamagedChunk> errors;
    const std::vector<Read> on = readOnWithReader(damaged, &errors);
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_EQ(errors[0].position(), chunk);
    const size_t lost = errors[0].skipped().size();
    ASSERT_EQ(on.size() + lost, all.size());
    for (size_t i = 0; i < on.size(); ++i) EXPECT_TRUE(on[i] == all[i < got.size() ? i : i + lost]) << "message " << i;
  }
}

// The first two chunks, read and checked side by side, both decoding to other bytes (their last
// literals changed): each is an error when it is reached, the first's not hiding the second's.
TEST(BagFileReader, TwoChunksCheckedSideBySideAreEachNamedAndReadingGoesOn) {
  const std::string dir = tempDir("viper_bag_reader_"), intact = dir + "/intact.bag", damaged = dir + "/damaged.bag";
  writeTextBag(intact, rosbag::compression::LZ4);
  std::string bytes = readFile(intact);
  std::vector<size_t> chunks;
  for (size_t field = bytes.find("compression=lz4"); chunks.size() < 2; field = bytes.find("compression=lz4", field + 1)) {
    ASSERT_NE(field, std::string::npos);
    const size_t chunk = field - 8;
    uint32_t header_size, data_size;
    std::memcpy(&header_size, bytes.data() + chunk, 4);
    std::memcpy(&data_size, bytes.data() + chunk + 4 + header_size, 4);
    const size_t last_literal = chunk + 8 + header_size + data_size - 9;
    bytes[last_literal] = static_cast<char>(bytes[last_literal] ^ 0x20);
    chunks.push_back(chunk);
  }
  writeFile(damaged, bytes);
  const std::vector<Read> all = readWithRosbag(intact);
  std::vector<viper::dataset::BagDamagedChunk> errors;
  const std::vector<Read> on = readOnWithReader(damaged, &errors);
  ASSERT_EQ(errors.size(), 2u);
  size_t lost = 0;
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(errors[k].position(), chunks[k]);
    EXPECT_NE(std::string(errors[k].what()).find("ERROR_contentChecksum_invalid"), std::string::npos) << errors[k].what();
    lost += errors[k].skipped().size();
  }
  ASSERT_EQ(on.size() + lost, all.size());
  for (size_t i = 0; i < on.size(); ++i) EXPECT_TRUE(on[i] == all[i + lost]) << "message " << i;
}

// The index's second entry pointing past its chunk (rosbag writes an index record's fields by name:
// conn, count, op, ver; then its data's length and the entries, sec, nsec, offset).
TEST(BagFileReader, AnIndexOffsetPastItsChunkIsNamed) {
  const std::string dir = tempDir("viper_bag_reader_"), path = dir + "/offset.bag";
  writeTextBag(dir + "/intact.bag", rosbag::compression::Uncompressed);
  std::string bytes = readFile(dir + "/intact.bag");
  const size_t op = bytes.find(std::string("op=\x04", 4)), chunk = bytes.find("compression=none") - 8;
  ASSERT_NE(op, std::string::npos);
  const uint32_t offset = 0xFFFFFF00u;
  std::memcpy(bytes.data() + op + 4 + 4 + 8 + 4 + 12 + 8, &offset, 4);
  writeFile(path, bytes);
  std::string error;
  const std::vector<Read> got = readWithReader(path, &error), all = readWithRosbag(dir + "/intact.bag");
  EXPECT_NE(error.find(path + ": damaged chunk at byte " + std::to_string(chunk) + ": the record at offset " +
                       std::to_string(offset)),
            std::string::npos)
      << error;
  ASSERT_EQ(got.size(), 1u) << "the message before";
  EXPECT_TRUE(got[0] == all[0]);
}

// Bytes flipped anywhere, or the file cut anywhere: the reader reads or throws std::runtime_error,
// and never reads outside what it holds (run under a sanitizer to see that).
TEST(BagFileReader, DamageAnywhereIsAnErrorNotACrash) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeWithRosbag(dir + "/small.bag", rosbag::compression::LZ4);
  const std::string whole = readFile(dir + "/small.bag");
  std::mt19937 random(1);
  int errors = 0;
  for (int i = 0; i < 300; ++i) {
    std::string bytes = whole;
    if (i % 3 == 0) {
      bytes.resize(random() % bytes.size());
    } else {
      const size_t at = random() % bytes.size();
      for (size_t k = at; k < std::min(bytes.size(), at + 1 + random() % 8); ++k) bytes[k] = static_cast<char>(random());
    }
    writeFile(dir + "/damaged.bag", bytes);
    std::string error;
    readWithReader(dir + "/damaged.bag", &error);
    errors += !error.empty();
    std::vector<viper::dataset::BagDamagedChunk> damaged;
    readOnWithReader(dir + "/damaged.bag", &damaged);  // and reading on after damaged chunks
  }
  EXPECT_GT(errors, 100) << "most damage is noticed";
}

// A missing file, a text file, a damaged chunk (after the messages before it): BagReadError, its
// what() naming the file, its problem() what is wrong without the file's name.
TEST(BagReader, ErrorsNameTheFile) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeFile(dir + "/text.bag", "not a bag\n");
  for (const std::string& path : {dir + "/missing.bag", dir + "/text.bag"}) {
    try {
      viper::BagReader bag(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const viper::BagReadError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": " + e.problem());
      EXPECT_FALSE(e.problem().empty());
      std::cout << e.what() << "\n";
    }
  }
  writeTextBag(dir + "/intact.bag", rosbag::compression::LZ4);
  const size_t chunk = damageThirdChunk(dir + "/intact.bag", "lz4", dir + "/damaged.bag");
  ASSERT_NE(chunk, std::string::npos);
  const std::vector<Read> all = readWithRosbag(dir + "/intact.bag");
  viper::BagReader reader(dir + "/damaged.bag", {"/text"});
  viper::BagReadMessage m;
  size_t read = 0;
  try {
    while (reader.next(m)) {
      ASSERT_LT(read, all.size());
      EXPECT_EQ(std::vector<uint8_t>(m.data(), m.data() + m.size()), all[read].bytes) << "message " << read;
      ++read;
    }
    ADD_FAILURE() << "no error";
  } catch (const viper::BagReadError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(dir + "/damaged.bag: damaged chunk at byte " + std::to_string(chunk), 0), 0u)
        << e.what();
    EXPECT_EQ(e.problem().rfind("damaged chunk at byte ", 0), 0u) << e.problem();
  }
  EXPECT_GT(read, 0u);
}

std::vector<Read> ofTopic(const std::vector<Read>& all, const std::string& topic) {
  std::vector<Read> out;
  for (const Read& r : all)
    if (r.topic == topic) out.push_back(r);
  return out;
}

// A damaged chunk that holds none of the topics asked for is not read, by BagReader nor by
// BagFileReader with that selection: every message asked for comes, no error.
TEST(BagReader, ADamagedChunkOfOtherTopicsIsNotRead) {
  withDamagedChunk(writeOneMessageChunks, 4, [](const std::string& damaged, size_t chunk, const std::vector<Read>& all) {
    ASSERT_EQ(all.size(), 12u);  // the damaged chunk: /b at time 4
    const std::vector<Read> a = ofTopic(all, "/a");
    ASSERT_EQ(a.size(), 6u);
    std::string error;
    readWithReader(damaged, &error);
    EXPECT_NE(error.find("damaged chunk at byte " + std::to_string(chunk) + ": "), std::string::npos)
        << "the whole bag's reading meets it: " << error;

    EXPECT_TRUE(readWithBagReader(damaged, Topics({"/a"})) == a);
    EXPECT_EQ(viper::BagReader(damaged, {"/a"}).size(), 6u);
    const std::function<bool(const viper::dataset::BagConnection&)> only_a =
        [](const viper::dataset::BagConnection& c) { return c.topic == "/a"; };
    EXPECT_TRUE(readOnWithReader(damaged, nullptr, &only_a) == a);
    BagFileReader selected(damaged);
    selected.select(only_a);
    EXPECT_EQ(selected.messageCount(), 6u);
    EXPECT_EQ(selected.connections().size(), 2u) << "the whole bag's connections";
    viper::dataset::BagMessage m;
    ASSERT_TRUE(selected.next(m));
    EXPECT_THROW(selected.select(only_a), std::logic_error) << "a selection after next()";
  });
}

// A damaged chunk of the topics asked for: BagReadError once, naming the chunk, with its message
// skipped; the next call reads on with the next chunk's messages. BagFileReader over every topic
// the same (the damaged chunk is read ahead there, with the one before it).
TEST(BagReader, ADamagedChunkIsAnErrorOnceThenReadingGoesOn) {
  withDamagedChunk(writeOneMessageChunks, 3, [](const std::string& damaged, size_t chunk, std::vector<Read> all) {
    ASSERT_EQ(all.size(), 12u);  // the damaged chunk: /a at time 3
    std::vector<Read> a = ofTopic(all, "/a");
    ASSERT_EQ(a[1].sec, 3u);
    a.erase(a.begin() + 1);
    ASSERT_EQ(all[2].sec, 3u);
    all.erase(all.begin() + 2);

    viper::BagReader reader(damaged, {"/a"});
    viper::BagReadMessage m;
    std::vector<Read> got;
    size_t errors = 0;
    for (;;) {
      try {
        if (!reader.next(m)) break;
        got.push_back(readOf(m));
      } catch (const viper::BagReadError& e) {
        ++errors;
        EXPECT_EQ(got.size(), 1u) << "after the message before it";
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": ", 0), 0u) << what;
        EXPECT_NE(what.find("(1 message skipped)"), std::string::npos) << what;
        ASSERT_EQ(e.skipped().size(), 1u);
        EXPECT_EQ(e.skipped()[0].topic(), "/a");
        EXPECT_EQ(e.skipped()[0].time, ros::Time(3, 0));
        ASSERT_LT(errors, 5u);
      }
    }
    EXPECT_EQ(errors, 1u);
    EXPECT_TRUE(got == a);

    std::vector<viper::dataset::BagDamagedChunk> damages;
    EXPECT_TRUE(readOnWithReader(damaged, &damages) == all);
    ASSERT_EQ(damages.size(), 1u);
    EXPECT_EQ(damages[0].position(), chunk);
    ASSERT_EQ(damages[0].skipped().size(), 1u);
    EXPECT_EQ(damages[0].skipped()[0].sec, 3u);
  });
}

}  // namespace
