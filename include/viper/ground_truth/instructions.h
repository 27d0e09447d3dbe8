// Which vector instructions the per-pixel kernels of the core use (flow, the depth conversions of
// camera_model.h, the class pictures of semantic_overlay.h). Each kernel says what its paths have in
// common; the choice is there for comparing the paths (tests, benchmarks), the default is fastest.
#pragma once

namespace viper {

/// A path through a per-pixel kernel, widest first (kAvx512Vbmi, kAvx512, kAvx2, kScalar).
enum class Instructions {
  kWidest,      ///< the widest this CPU has
  kAvx512,      ///< AVX-512 F, BW, VL, DQ (with AVX2 and FMA)
  kAvx2,        ///< AVX2 and FMA
  kScalar,      ///< one pixel at a time
  kAvx512Vbmi,  ///< kAvx512 and AVX-512 VBMI (byte permutes); kernels without such a path take kAvx512
};

/// The path a kernel takes on this CPU when asked for `requested`: a path the CPU lacks falls back
/// to the widest it has below it. VIPER_INSTRUCTIONS=avx512vbmi|avx512|avx2|scalar (read once)
/// caps every request at that path, as if the CPU had no wider one.
Instructions instructionsUsed(Instructions requested);

}  // namespace viper
