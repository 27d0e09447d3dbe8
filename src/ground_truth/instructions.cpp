#include "viper/ground_truth/instructions.h"

#include "x86_kernels.h"

namespace viper {

Instructions instructionsUsed(Instructions requested) {
#ifdef VIPER_X86
  static const bool avx2 =
      __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("popcnt");
  static const bool avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                             __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
  static const bool vbmi = avx512 && __builtin_cpu_supports("avx512vbmi");
  if ((requested == Instructions::kWidest || requested == Instructions::kAvx512Vbmi) && vbmi)
    return Instructions::kAvx512Vbmi;
  if (requested == Instructions::kWidest || requested == Instructions::kAvx512Vbmi ||
      requested == Instructions::kAvx512)
    return avx512 ? Instructions::kAvx512 : avx2 ? Instructions::kAvx2 : Instructions::kScalar;
  if (requested == Instructions::kAvx2) return avx2 ? Instructions::kAvx2 : Instructions::kScalar;
#else
  (void)requested;
#endif
  return Instructions::kScalar;
}

}  // namespace viper
