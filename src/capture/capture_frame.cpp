#include "viper/capture/capture_frame.h"

#include <algorithm>
#include <string>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

// An AVX2 path chosen at run time needs x86-64 and a compiler that takes __attribute__((target))
// and __builtin_cpu_supports (as the ground-truth kernels' VIPER_X86, x86_kernels.h there).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define VIPER_X86 1
#endif

namespace viper {
namespace {

// One loop, inlined into a function compiled for AVX2 (vpmaxud, 8 ids a step) and into the baseline.
__attribute__((always_inline)) inline uint32_t largestOf(const uint32_t* ids, size_t n) {
  uint32_t largest = 0;
  for (size_t p = 0; p < n; ++p) largest = std::max(largest, ids[p]);
  return largest;
}

#ifdef VIPER_X86
__attribute__((target("avx2"))) uint32_t largestAvx2(const uint32_t* ids, size_t n) { return largestOf(ids, n); }
#endif

std::string sizeProblem(const char* name, size_t actual, size_t expected, const CaptureFrame& f, int channels) {
  if (actual == expected) return {};
  return std::string(name) + " has " + std::to_string(actual) + " elements, expected " + std::to_string(expected) +
         " (" + std::to_string(f.width) + "x" + std::to_string(f.height) + "x" + std::to_string(channels) + ")";
}

}  // namespace

std::string validateFrame(const CaptureFrame& f) { return validateFrame(f, FrameImagesElsewhere{}); }

std::string validateFrame(const CaptureFrame& f, const FrameImagesElsewhere& elsewhere) {
  const std::string at = "frame " + std::to_string(f.number) + ": ";
  const size_t pixels = f.pixelCount();
  for (const std::string& problem :
       {elsewhere.color_rgb ? std::string() : sizeProblem("color_rgb", f.color_rgb.size(), pixels * 3, f, 3),
        elsewhere.depth_window ? std::string() : sizeProblem("depth_window", f.depth_window.size(), pixels, f, 1),
        elsewhere.draw_ids ? std::string() : sizeProblem("draw_ids", f.draw_ids.size(), pixels, f, 1),
        elsewhere.primitive_ids ? std::string() : sizeProblem("primitive_ids", f.primitive_ids.size(), pixels, f, 1)}) {
    if (!problem.empty()) return at + problem;
  }
  for (size_t i = 0; i < f.draws.size(); ++i) {
    const DrawRecord& d = f.draws[i];
    if (d.index != i)
      return at + "draw " + std::to_string(i) + " has index " + std::to_string(d.index) +
             " (draw indices must be 0..n-1 in order)";
    if (d.gaps & ~(kGapNoIds | kGapMatrixMissing | kGapNoMesh))
      return at + "draw " + std::to_string(i) + " has unknown gap bits " + std::to_string(d.gaps);
    if (d.deformed_clip_xyzw.size() % 4 != 0)
      return at + "draw " + std::to_string(i) + " deformed_clip_xyzw has " +
             std::to_string(d.deformed_clip_xyzw.size()) + " floats, not a multiple of 4";
  }
  for (const MeshRecord& m : f.new_meshes) {
    if (m.positions_xyz.size() % 3 != 0 || m.indices.size() % 3 != 0)
      return at + "mesh " + std::to_string(m.key) + " has " + std::to_string(m.positions_xyz.size()) +
             " position floats and " + std::to_string(m.indices.size()) + " indices (both must be multiples of 3)";
    const size_t vertices = m.positions_xyz.size() / 3;
    for (uint32_t index : m.indices) {
      if (index >= vertices)
        return at + "mesh " + std::to_string(m.key) + " index " + std::to_string(index) + " is past its " +
               std::to_string(vertices) + " vertices";
    }
  }
  if (elsewhere.draw_id_range_later) return {};
  const uint32_t* ids = elsewhere.draw_ids ? elsewhere.draw_ids : f.draw_ids.data();
  return drawIdsProblem(f, ids, largestDrawId(ids, pixels));
}

std::string drawIdsProblem(const CaptureFrame& f, const uint32_t* ids, uint32_t largest) {
  // The largest id first; only a frame with a bad id is searched.
  const size_t draws = f.draws.size(), pixels = f.pixelCount();
  for (size_t p = 0; largest > draws && p < pixels; ++p) {
    if (ids[p] > draws)
      return "frame " + std::to_string(f.number) + ": pixel (" + std::to_string(p % f.width) + ", " +
             std::to_string(p / f.width) + ") has draw id " + std::to_string(ids[p]) +
             " but the draw list has only " + std::to_string(draws) + " draws";
  }
  return {};
}

// Where the draw id is 0, the mask is -1: -1 | p = -1, 0 | p = p. This library is built at -O2, where
// GCC does not vectorise a loop whose output may overlap its input; the plain loop cost a 1080p
// frame about 1.5 ms of the bridge's time (perf).
void maskPrimitiveIds(const uint32_t* ids, const uint32_t* primitives, size_t n, int32_t* out) {
  size_t i = 0;
#ifdef __SSE2__
  const __m128i zero = _mm_setzero_si128();
  for (; i + 4 <= n; i += 4) {
    const __m128i none = _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + i)), zero);
    const __m128i p = _mm_loadu_si128(reinterpret_cast<const __m128i*>(primitives + i));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_or_si128(p, none));
  }
#endif
  for (; i < n; ++i) out[i] = ids[i] == 0 ? -1 : static_cast<int32_t>(primitives[i]);
}

uint32_t largestDrawId(const uint32_t* ids, size_t n) {
#ifdef VIPER_X86
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) return largestAvx2(ids, n);
#endif
  return largestOf(ids, n);
}

}  // namespace viper
