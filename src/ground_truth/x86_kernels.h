// Internal to viper_core: whether the vector kernels (flow_avx2.cpp, flow_avx512.cpp,
// pixel_kernels_avx2.cpp, pixel_kernels_avx512.cpp) are compiled, which needs x86-64 and a compiler
// that takes __attribute__((target)) and __builtin_cpu_supports.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define VIPER_X86 1
#endif
