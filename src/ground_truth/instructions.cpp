#include "viper/ground_truth/instructions.h"

#include "x86_kernels.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace viper {

namespace {

// VIPER_INSTRUCTIONS=avx512vbmi|avx512|avx2|scalar: the widest path any kernel may take, as if the
// CPU had no more (to compare a CPU's paths natively, or to make the files another CPU would).
int widestAllowed() {
  static const int allowed = [] {
    const char* v = std::getenv("VIPER_INSTRUCTIONS");
    if (!v || !*v) return 3;
    const char* names[] = {"scalar", "avx2", "avx512", "avx512vbmi"};
    for (int i = 0; i < 4; ++i)
      if (std::strcmp(v, names[i]) == 0) return i;
    std::fprintf(stderr, "[viper] VIPER_INSTRUCTIONS=%s is not one of avx512vbmi, avx512, avx2, scalar: ignored\n", v);
    return 3;
  }();
  return allowed;
}

}  // namespace

Instructions instructionsUsed(Instructions requested) {
#ifdef VIPER_X86
  static const int allowed = widestAllowed();
  static const bool avx2 = allowed >= 1 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                           __builtin_cpu_supports("popcnt");
  static const bool avx512 = allowed >= 2 && avx2 && __builtin_cpu_supports("avx512f") &&
                             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl") &&
                             __builtin_cpu_supports("avx512dq");
  static const bool vbmi = allowed >= 3 && avx512 && __builtin_cpu_supports("avx512vbmi");
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
