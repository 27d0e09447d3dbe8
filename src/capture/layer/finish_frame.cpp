#include "finish_frame.h"

#include <algorithm>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define VIPER_FINISH_AVX2 1
#define VIPER_AVX2 __attribute__((target("avx2")))
#endif

namespace viper {
namespace capture {
namespace {

// The largest float below 2^31: larger primitive ids (beyond float's exact integers anyway) are
// clamped to it, so that both paths convert them alike.
constexpr float kMaxPrimitive = 2147483520.0f;

// What one row of the output is made from.
struct Row {
  const uint8_t* rgba;        // null: no color
  const float* depth;         // float depth, or null
  const uint32_t* depth_24_8;  // packed depth24/stencil8, or null
  const float* ids;           // (draw id, primitive id) pairs, or null
  uint8_t* rgb;
  float* depth_window;
  uint32_t* draw_ids;
  uint32_t* primitive_ids;
};

// Pixels x0..w-1 of a row, one at a time; counts visible pixels per draw id into visible.
void scalarPixels(const Row& r, size_t x0, size_t w, float max_id, uint32_t* visible) {
  for (size_t x = x0; x < w; ++x) {
    if (r.rgba) {
      const uint8_t* s = r.rgba + 4 * x;
      uint8_t* d = r.rgb + 3 * x;
      d[0] = s[0], d[1] = s[1], d[2] = s[2];
    }
    if (r.depth_24_8) r.depth_window[x] = static_cast<float>(r.depth_24_8[x] >> 8) * (1.0f / 16777215.0f);
    if (!r.ids) continue;
    const float id = r.ids[2 * x];
    if (!(id >= 1.0f) || id > max_id) {  // also rejects NaN
      r.draw_ids[x] = r.primitive_ids[x] = 0;
      continue;
    }
    const uint32_t draw_id = static_cast<uint32_t>(id + 0.5f);
    r.draw_ids[x] = draw_id;
    r.primitive_ids[x] = static_cast<uint32_t>(std::min(std::max(0.0f, r.ids[2 * x + 1]), kMaxPrimitive) + 0.5f);
    ++visible[draw_id];
  }
}

#ifdef VIPER_FINISH_AVX2
// Pixels 0.. of a row in blocks of 8, as far as they go while leaving the 4 bytes that the color
// stores write past a block inside the row; returns where the rest begins.
VIPER_AVX2 size_t avx2Pixels(const Row& r, size_t w, float max_id, uint32_t* visible) {
  const size_t end = w >= 10 ? (w - 2) & ~size_t(7) : 0;
  // Per 128-bit lane: bytes 0-2, 4-6, 8-10, 12-14 (RGB of 4 pixels) to the front.
  const __m256i rgb_of_rgba = _mm256_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1, 0, 1, 2, 4, 5,
                                               6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
  const __m256 one = _mm256_set1_ps(1.0f), max_v = _mm256_set1_ps(max_id), half = _mm256_set1_ps(0.5f),
               zero = _mm256_setzero_ps(), max_primitive = _mm256_set1_ps(kMaxPrimitive), depth_scale = _mm256_set1_ps(1.0f / 16777215.0f);
  for (size_t x = 0; x < end; x += 8) {
    if (r.rgba) {
      const __m256i rgb =
          _mm256_shuffle_epi8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(r.rgba + 4 * x)), rgb_of_rgba);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(r.rgb + 3 * x), _mm256_castsi256_si128(rgb));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(r.rgb + 3 * x + 12), _mm256_extracti128_si256(rgb, 1));
    }
    if (r.depth_24_8) {
      const __m256i packed = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r.depth_24_8 + x));
      _mm256_storeu_ps(r.depth_window + x,
                       _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(packed, 8)), depth_scale));
    }
    if (!r.ids) continue;
    const __m256 a = _mm256_loadu_ps(r.ids + 2 * x), b = _mm256_loadu_ps(r.ids + 2 * x + 8);
    // shuffle_ps works within lanes: (a0 a2 b0 b2 | a4 a6 b4 b6); the 64-bit permute restores order.
    const __m256 id = _mm256_castpd_ps(
        _mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0))), 0xD8));
    const __m256 primitive = _mm256_castpd_ps(
        _mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1))), 0xD8));
    const __m256i valid = _mm256_castps_si256(
        _mm256_and_ps(_mm256_cmp_ps(id, one, _CMP_GE_OQ), _mm256_cmp_ps(id, max_v, _CMP_LE_OQ)));
    const __m256i draw = _mm256_and_si256(_mm256_cvttps_epi32(_mm256_add_ps(id, half)), valid);
    // max_ps returns its second operand (0) where the primitive id is NaN, as std::max(0, NaN) does.
    const __m256i prim = _mm256_and_si256(
        _mm256_cvttps_epi32(_mm256_add_ps(_mm256_min_ps(_mm256_max_ps(primitive, zero), max_primitive), half)), valid);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(r.draw_ids + x), draw);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(r.primitive_ids + x), prim);
    const uint32_t first = r.draw_ids[x];
    const int same = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(draw, _mm256_set1_epi32(first))));
    if (same == 0xff) {
      visible[first] += 8;
    } else {
      for (size_t k = 0; k < 8; ++k) ++visible[r.draw_ids[x + k]];
    }
  }
  return end;
}
#endif

void finish(const RawImages& raw, CaptureFrame& frame, bool vectorised) {
  const size_t w = static_cast<size_t>(raw.width), h = static_cast<size_t>(raw.height);
  frame.width = static_cast<uint32_t>(w);
  frame.height = static_cast<uint32_t>(h);
  const size_t n = w * h;
  // Every element is written below; resize keeps recycled memory without refilling it.
  frame.color_rgb.resize(n * 3);
  frame.depth_window.resize(n);
  frame.draw_ids.resize(n);
  frame.primitive_ids.resize(n);
  // Counts per draw id; index 0 (no draw) counts too, and is dropped.
  std::vector<uint32_t> visible(frame.draws.size() + 1, 0);
  // The images in their vectors, or where the views point (asynchronous read-back).
  const uint8_t* rgba = raw.rgba_view ? raw.rgba_view : raw.rgba.size() >= n * 4 ? raw.rgba.data() : nullptr;
  const float* ids = raw.ids_view ? raw.ids_view : raw.ids.size() >= n * 2 ? raw.ids.data() : nullptr;
  const uint32_t* depth_24_8 = raw.depth_24_8_view            ? raw.depth_24_8_view
                               : raw.depth_24_8.size() >= n ? raw.depth_24_8.data()
                                                            : nullptr;
  const float* depth = raw.depth_view ? raw.depth_view : raw.depth.size() >= n ? raw.depth.data() : nullptr;
  const bool has_color = rgba != nullptr, has_ids = ids != nullptr;
  const bool depth_packed = depth_24_8 != nullptr, depth_float = !depth_packed && depth != nullptr;
  const float max_id = static_cast<float>(frame.draws.size());
#ifdef VIPER_FINISH_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2");
  vectorised = vectorised && avx2;
#else
  vectorised = false;
#endif
  for (size_t y = 0; y < h; ++y) {
    const size_t src = (h - 1 - y) * w, dst = y * w;  // GL rows are bottom-up
    const size_t scene_src = raw.depth_ids_top_first ? dst : src;
    const Row r{has_color ? rgba + src * 4 : nullptr,
                depth_float ? depth + scene_src : nullptr,
                depth_packed ? depth_24_8 + scene_src : nullptr,
                has_ids ? ids + scene_src * 2 : nullptr,
                &frame.color_rgb[dst * 3],
                &frame.depth_window[dst],
                &frame.draw_ids[dst],
                &frame.primitive_ids[dst]};
    if (!has_color) std::memset(r.rgb, 0, w * 3);
    if (r.depth) std::memcpy(r.depth_window, r.depth, w * sizeof(float));
    if (!depth_float && !depth_packed) std::fill_n(r.depth_window, w, 1.0f);
    if (!has_ids) {
      std::fill_n(r.draw_ids, w, 0u);
      std::fill_n(r.primitive_ids, w, 0u);
    }
    size_t x = 0;
#ifdef VIPER_FINISH_AVX2
    if (vectorised) x = avx2Pixels(r, w, max_id, visible.data());
#endif
    scalarPixels(r, x, w, max_id, visible.data());
  }
  for (size_t i = 0; i < frame.draws.size(); ++i) frame.draws[i].visible_pixels = visible[i + 1];
}

}  // namespace

void finishFrame(const RawImages& raw, CaptureFrame& frame) { finish(raw, frame, true); }

void finishFrameScalar(const RawImages& raw, CaptureFrame& frame) { finish(raw, frame, false); }

}  // namespace capture
}  // namespace viper
