// XXH32 of several streams side by side (bag_player's LZ4 content checksums) against libxxhash's
// XXH32 of each stream whole: streams of every length around the 16-byte stripe, cut into pieces
// anywhere (a piece boundary inside a stripe, empty pieces), one to six streams at once.
#include "../../src/dataset/bag/xxh32_streams.h"

#include <xxhash.h>

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace {

using viper::dataset::detail::BytePiece;
using viper::dataset::detail::xxh32Streams;

// `bytes` cut into pieces at random places, some of them empty.
std::vector<BytePiece> cut(const std::vector<uint8_t>& bytes, std::mt19937& random) {
  std::vector<size_t> at = {0, bytes.size()};
  const size_t cuts = random() % 5;
  for (size_t i = 0; i < cuts; ++i) at.push_back(bytes.empty() ? 0 : random() % (bytes.size() + 1));
  std::sort(at.begin(), at.end());
  std::vector<BytePiece> pieces;
  for (size_t i = 0; i + 1 < at.size(); ++i) pieces.push_back({bytes.data() + at[i], at[i + 1] - at[i]});
  return pieces;
}

TEST(Xxh32Streams, EachStreamHashesAsLibxxhashHashesItWhole) {
  std::mt19937 random(11);
  std::cout << "side by side: " << viper::dataset::detail::xxh32StreamsKernel() << "\n";
  for (int round = 0; round < 400; ++round) {
    const size_t count = 1 + random() % 6;
    std::vector<std::vector<uint8_t>> bytes(count);
    std::vector<std::vector<BytePiece>> pieces(count);
    std::vector<const std::vector<BytePiece>*> streams;
    for (size_t i = 0; i < count; ++i) {
      // Short streams (the tail rounds only), lengths around stripes, and long ones.
      const size_t size = round % 4 == 0 ? random() % 40 : round % 4 == 1 ? random() % 300 : 1000 + random() % 70000;
      bytes[i].resize(size);
      for (uint8_t& b : bytes[i]) b = static_cast<uint8_t>(random());
      pieces[i] = cut(bytes[i], random);
      streams.push_back(&pieces[i]);
    }
    std::vector<uint32_t> got(count);
    xxh32Streams(streams, got.data());
    for (size_t i = 0; i < count; ++i)
      ASSERT_EQ(got[i], XXH32(bytes[i].data(), bytes[i].size(), 0))
          << "round " << round << ", stream " << i << " of " << count << ", " << bytes[i].size() << " bytes in "
          << pieces[i].size() << " pieces";
  }
}

TEST(Xxh32Streams, NoStreamsAndEmptyStreams) {
  xxh32Streams({}, nullptr);
  const std::vector<BytePiece> none, empty_pieces = {{nullptr, 0}, {nullptr, 0}};
  uint32_t h[2];
  xxh32Streams({&none, &empty_pieces}, h);
  EXPECT_EQ(h[0], XXH32(nullptr, 0, 0));
  EXPECT_EQ(h[1], XXH32(nullptr, 0, 0));
}

}  // namespace
