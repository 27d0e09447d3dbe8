// Internal to viper_core: the per-pixel kernels of the class pictures (semantic_overlay.cpp) and of
// the depth conversions (camera_model.cpp) in blocks of AVX2 (pixel_kernels_avx2.cpp) and AVX-512
// (pixel_kernels_avx512.cpp, the class pictures also with VBMI) vectors, for CPUs that have those
// instructions. Each does the whole blocks at the start of its pixels and returns how many pixels
// that is; the caller does the rest one at a time with its scalar code, which the kernels
// reproduce bit for bit: the same integer and IEEE double operations in the same order, compiled
// without contracting multiply-adds (VIPER_NO_FP_CONTRACT: a fused multiply-add rounds once where
// the scalar code rounds twice; the products are mostly of floats, exact in double, but not all:
// test_camera_model has a case).
#pragma once

#include "viper/ground_truth/instructions.h"
#include "x86_kernels.h"

#include <cstddef>
#include <cstdint>

// GCC contracts across statements (its default -ffp-contract=fast), also the vector operators its
// intrinsics are; clang only within one expression, and `#pragma clang fp contract(off)` at the top
// of the kernels' files stops that.
#if defined(__clang__)
#define VIPER_NO_FP_CONTRACT
#else
#define VIPER_NO_FP_CONTRACT __attribute__((optimize("fp-contract=off")))
#endif

namespace viper {
namespace pixel_kernels {

// Depth conversions: rows 2 and 3 of the projection of each draw id (slot 0 as the caller defines
// it), NaN where a draw has none: NaN makes every pixel of such a draw fail the kernels' checks,
// as the scalar code's missing projection does.
struct DepthRows {
  const double *p22, *p23, *p32, *p33;
  uint32_t size;  // ids >= size are slot 0
};

// Per-slot counts of pixels with and without depth (windowDepth*): summed in registers while the
// blocks stay on one slot, into `good` and `bad` when the slot changes and at the end.
struct SlotCounts {
  uint32_t *good, *bad;
  uint32_t slot = 0, with = 0, without = 0;
  // The lanes of a block in `lanes` are of slot s, those in `ok` have depth.
  void add(uint32_t s, uint32_t lanes, uint32_t ok) {
    if (s != slot) {
      good[slot] += with, bad[slot] += without;
      slot = s, with = without = 0;
    }
    with += static_cast<uint32_t>(__builtin_popcount(lanes & ok));
    without += static_cast<uint32_t>(__builtin_popcount(lanes & ~ok));
  }
  void flush() { good[slot] += with, bad[slot] += without; }
};

// The path the kernels below take for `requested` (pixel_kernels.cpp): kScalar where this build has
// no vector kernels or the CPU none of their instructions.
Instructions kernelPath(Instructions requested);

// The kernel of `path` (not kScalar), as below.
size_t colorize(Instructions path, const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb);
size_t overlay(Instructions path, const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette,
               int weight, uint8_t* rgb);
size_t depthMetres(Instructions path, const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                   float* metres);
size_t depthMetresMasking(Instructions path, const uint32_t* ids, const float* window, size_t n,
                          const DepthRows& rows, float* metres, int32_t* primitives, uint32_t& largest);
size_t windowDepth(Instructions path, const uint32_t* ids, const float* metres, size_t n, const DepthRows& rows,
                   float* window, uint32_t* good, uint32_t* bad);
// VIPER's instance picture (encodeViperInstances); every vector path takes the AVX2 kernel.
size_t encodeViper(Instructions path, const uint8_t* class_ids, const int32_t* instance_ids, size_t n, uint8_t* rgb);

#ifdef VIPER_X86
// Class pictures: `palette` holds 256 class colors as r | g << 8 | b << 16, indexed by class id.
// Overlay blends with the 8.8 fixed-point weight `weight`, 0..256.
size_t colorizeAvx2(const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb);
size_t encodeViperAvx2(const uint8_t* class_ids, const int32_t* instance_ids, size_t n, uint8_t* rgb);
size_t colorizeAvx512(const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb);
size_t overlayAvx2(const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette, int weight,
                   uint8_t* rgb);
size_t overlayAvx512(const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette, int weight,
                     uint8_t* rgb);
// With AVX-512 VBMI: the palette's channels looked up with byte permutes instead of gathers.
size_t colorizeAvx512Vbmi(const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb);
size_t overlayAvx512Vbmi(const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette, int weight,
                         uint8_t* rgb);

// depthMetres: `ids` null = every pixel slot 0. Writes NaN (quiet, no payload) where there is no
// depth.
size_t depthMetresAvx2(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows, float* metres);
size_t depthMetresAvx512(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows, float* metres);
// depthMetres and, in the same pass over the ids (not null): `largest` of them, and the
// primitive ids at `primitives` set to -1 where the draw id is 0 (camera_model.h).
size_t depthMetresMaskingAvx2(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows, float* metres,
                              int32_t* primitives, uint32_t& largest);
size_t depthMetresMaskingAvx512(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                                float* metres, int32_t* primitives, uint32_t& largest);

// windowDepthFromMetres: writes 1 where there is no depth, and counts per slot the pixels with
// (good) and without (bad) depth; slot 0's counts mean nothing.
size_t windowDepthAvx2(const uint32_t* ids, const float* metres, size_t n, const DepthRows& rows, float* window,
                       uint32_t* good, uint32_t* bad);
size_t windowDepthAvx512(const uint32_t* ids, const float* metres, size_t n, const DepthRows& rows, float* window,
                         uint32_t* good, uint32_t* bad);
#endif

}  // namespace pixel_kernels
}  // namespace viper
