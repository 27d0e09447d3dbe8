#include "xxh32_streams.h"

#include <algorithm>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define VIPER_XXH_X86 1
#include <immintrin.h>
// GCC 12's AVX-512 intrinsics initialise their undefined operands from themselves, which
// -Wmaybe-uninitialized reports at every use (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace viper::dataset::detail {

namespace {

constexpr uint32_t kP1 = 2654435761u, kP2 = 2246822519u, kP3 = 3266489917u, kP4 = 668265263u, kP5 = 374761393u;

uint32_t rotl(uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }

uint32_t load32(const uint8_t* p) { return p[0] | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

// One stream: where it is in its pieces, its four lanes, and the bytes of a stripe that spans two
// pieces (or, at the end, the fewer than 16 bytes left).
struct Stream {
  const std::vector<BytePiece>* pieces = nullptr;
  size_t piece = 0, at = 0;
  uint32_t acc[4] = {kP1 + kP2, kP2, 0, 0u - kP1};
  uint8_t carry[16] = {};
  size_t carry_len = 0;
  uint64_t total = 0;

  const BytePiece& current() const { return (*pieces)[piece]; }
  size_t left() const { return current().size - at; }

  void stripe(const uint8_t* p) {
    for (int i = 0; i < 4; ++i) acc[i] = rotl(acc[i] + load32(p + 4 * i) * kP2, 13) * kP1;
  }

  // Brings the stream to whole stripes in its current piece (carrying a stripe across pieces
  // through `carry`); false once fewer than 16 bytes are left in all, which are then in `carry`.
  bool ready() {
    for (;;) {
      while (piece < pieces->size() && at == current().size) ++piece, at = 0;
      if (piece == pieces->size()) return false;
      if (carry_len == 0 && left() >= 16) return true;
      const size_t take = std::min(16 - carry_len, left());
      std::memcpy(carry + carry_len, current().data + at, take);
      carry_len += take, at += take;
      if (carry_len == 16) stripe(carry), carry_len = 0;
    }
  }

  // The stripes of the current piece, one at a time.
  void runAlone() {
    const size_t steps = left() / 16;
    const uint8_t* p = current().data + at;
    for (size_t i = 0; i < steps; ++i) stripe(p + 16 * i);
    at += 16 * steps;
  }

  uint32_t finish() const {
    uint32_t h = total >= 16 ? rotl(acc[0], 1) + rotl(acc[1], 7) + rotl(acc[2], 12) + rotl(acc[3], 18) : kP5;
    h += static_cast<uint32_t>(total);
    size_t i = 0;
    for (; i + 4 <= carry_len; i += 4) h = rotl(h + load32(carry + i) * kP3, 17) * kP4;
    for (; i < carry_len; ++i) h = rotl(h + carry[i] * kP5, 11) * kP1;
    h ^= h >> 15;
    h *= kP2;
    h ^= h >> 13;
    h *= kP3;
    h ^= h >> 16;
    return h;
  }
};

#ifdef VIPER_XXH_X86
#define VIPER_XXH_AVX512 __attribute__((target("avx512f,avx512vl")))

// `steps` stripes of up to four streams side by side, one stream in each 128-bit lane (lanes past
// `k` read a zero stripe over and over, and are dropped).
VIPER_XXH_AVX512 void runSideBySide(Stream* const* s, int k, size_t steps) {
  alignas(64) static const uint8_t zeros[16] = {};
  const uint8_t* p[4];
  size_t stride[4];
  alignas(64) uint32_t acc[16] = {};
  for (int j = 0; j < 4; ++j) {
    p[j] = j < k ? s[j]->current().data + s[j]->at : zeros;
    stride[j] = j < k ? 16 : 0;
    if (j < k) std::memcpy(acc + 4 * j, s[j]->acc, sizeof(s[j]->acc));
  }
  const __m512i p1 = _mm512_set1_epi32(static_cast<int>(kP1)), p2 = _mm512_set1_epi32(static_cast<int>(kP2));
  __m512i a = _mm512_load_si512(acc);
  for (size_t i = 0; i < steps; ++i) {
    __m512i in = _mm512_castsi128_si512(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p[0] + stride[0] * i)));
    in = _mm512_inserti32x4(in, _mm_loadu_si128(reinterpret_cast<const __m128i*>(p[1] + stride[1] * i)), 1);
    in = _mm512_inserti32x4(in, _mm_loadu_si128(reinterpret_cast<const __m128i*>(p[2] + stride[2] * i)), 2);
    in = _mm512_inserti32x4(in, _mm_loadu_si128(reinterpret_cast<const __m128i*>(p[3] + stride[3] * i)), 3);
    a = _mm512_mullo_epi32(_mm512_rol_epi32(_mm512_add_epi32(a, _mm512_mullo_epi32(in, p2)), 13), p1);
  }
  _mm512_store_si512(acc, a);
  for (int j = 0; j < k; ++j) {
    std::memcpy(s[j]->acc, acc + 4 * j, sizeof(s[j]->acc));
    s[j]->at += 16 * steps;
  }
}

#define VIPER_XXH_AVX2 __attribute__((target("avx2")))
#define VIPER_XXH_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

// Two streams in one 256-bit register (x in the low half, y in the high): their accumulators, and
// stripe i of each.
VIPER_XXH_AVX2_INLINE __m256i halves(const void* x, const void* y) {
  return _mm256_inserti128_si256(_mm256_castsi128_si256(_mm_loadu_si128(static_cast<const __m128i*>(x))),
                                 _mm_loadu_si128(static_cast<const __m128i*>(y)), 1);
}

VIPER_XXH_AVX2_INLINE void storePair(__m256i a, Stream& x, Stream& y, size_t steps) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(x.acc), _mm256_castsi256_si128(a));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(y.acc), _mm256_extracti128_si256(a, 1));
  x.at += 16 * steps, y.at += 16 * steps;
}

// Two streams in one 256-bit register: half the work of the four-lane kernel for the common case.
VIPER_XXH_AVX512 void runPair(Stream& x, Stream& y, size_t steps) {
  const uint8_t* px = x.current().data + x.at;
  const uint8_t* py = y.current().data + y.at;
  const __m256i p1 = _mm256_set1_epi32(static_cast<int>(kP1)), p2 = _mm256_set1_epi32(static_cast<int>(kP2));
  __m256i a = halves(x.acc, y.acc);
  for (size_t i = 0; i < steps; ++i) {
    const __m256i sum = _mm256_add_epi32(a, _mm256_mullo_epi32(halves(px + 16 * i, py + 16 * i), p2));
    a = _mm256_mullo_epi32(_mm256_rol_epi32(sum, 13), p1);
  }
  storePair(a, x, y, steps);
}

// runPair without AVX-512's rotate: two shifts and an or. (On an AVX-512 Xeon runPair's rotate was
// 8-15 % faster than this kernel, two streams of 512 KB and of 8 MB, timed once by a program outside
// the repository (docs/pipeline_speed.md, session 19): so both are kept; the
// intrinsics' target attributes keep one template from holding the loop of both.)
VIPER_XXH_AVX2 void runPairAvx2(Stream& x, Stream& y, size_t steps) {
  const uint8_t* px = x.current().data + x.at;
  const uint8_t* py = y.current().data + y.at;
  const __m256i p1 = _mm256_set1_epi32(static_cast<int>(kP1)), p2 = _mm256_set1_epi32(static_cast<int>(kP2));
  __m256i a = halves(x.acc, y.acc);
  for (size_t i = 0; i < steps; ++i) {
    const __m256i sum = _mm256_add_epi32(a, _mm256_mullo_epi32(halves(px + 16 * i, py + 16 * i), p2));
    a = _mm256_mullo_epi32(_mm256_or_si256(_mm256_slli_epi32(sum, 13), _mm256_srli_epi32(sum, 19)), p1);
  }
  storePair(a, x, y, steps);
}

enum class Kernel { kScalar, kAvx2, kAvx512 };

Kernel kernel() {
  static const Kernel k = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? Kernel::kAvx512
                          : __builtin_cpu_supports("avx2")                                        ? Kernel::kAvx2
                                                                                                  : Kernel::kScalar;
  return k;
}
#endif

}  // namespace

const char* xxh32StreamsKernel() {
#ifdef VIPER_XXH_X86
  return kernel() == Kernel::kAvx512 ? "avx512" : kernel() == Kernel::kAvx2 ? "avx2" : "scalar";
#else
  return "scalar";
#endif
}

void xxh32Streams(const std::vector<const std::vector<BytePiece>*>& streams, uint32_t* hashes) {
  std::vector<Stream> all(streams.size());
  for (size_t i = 0; i < streams.size(); ++i) {
    all[i].pieces = streams[i];
    for (const BytePiece& p : *streams[i]) all[i].total += p.size;
  }
  std::vector<Stream*> active;
  for (Stream& s : all)
    if (s.ready()) active.push_back(&s);
#ifdef VIPER_XXH_X86
  // Side by side while two or more streams have whole stripes in their current pieces (AVX2: two
  // at a time).
  while (kernel() != Kernel::kScalar && active.size() >= 2) {
    const int k = kernel() == Kernel::kAvx2 ? 2 : static_cast<int>(std::min<size_t>(active.size(), 4));
    size_t steps = active[0]->left() / 16;
    for (int j = 1; j < k; ++j) steps = std::min(steps, active[j]->left() / 16);
    if (kernel() == Kernel::kAvx2) runPairAvx2(*active[0], *active[1], steps);
    else if (k == 2) runPair(*active[0], *active[1], steps);
    else runSideBySide(active.data(), k, steps);
    active.erase(std::remove_if(active.begin(), active.end(), [](Stream* s) { return !s->ready(); }), active.end());
  }
#endif
  for (Stream* s : active)
    do s->runAlone();
    while (s->ready());
  for (size_t i = 0; i < all.size(); ++i) hashes[i] = all[i].finish();
}

}  // namespace viper::dataset::detail
