#include "pixel_kernels.h"

namespace viper {
namespace pixel_kernels {

Instructions kernelPath(Instructions requested) {
#ifdef VIPER_X86
  return instructionsUsed(requested);
#else
  (void)requested;
  return Instructions::kScalar;
#endif
}

#ifdef VIPER_X86
size_t colorize(Instructions path, const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb) {
  return path == Instructions::kAvx512Vbmi ? colorizeAvx512Vbmi(ids, n, palette, rgb)
         : path == Instructions::kAvx512   ? colorizeAvx512(ids, n, palette, rgb)
                                           : colorizeAvx2(ids, n, palette, rgb);
}

size_t overlay(Instructions path, const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette,
               int weight, uint8_t* rgb) {
  return path == Instructions::kAvx512Vbmi ? overlayAvx512Vbmi(color, ids, n, palette, weight, rgb)
         : path == Instructions::kAvx512   ? overlayAvx512(color, ids, n, palette, weight, rgb)
                                           : overlayAvx2(color, ids, n, palette, weight, rgb);
}

// The depth conversions have no VBMI path of their own.
size_t depthMetres(Instructions path, const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                   float* metres) {
  return path == Instructions::kAvx2 ? depthMetresAvx2(ids, window, n, rows, metres)
                                     : depthMetresAvx512(ids, window, n, rows, metres);
}

size_t depthMetresMasking(Instructions path, const uint32_t* ids, const float* window, size_t n,
                          const DepthRows& rows, float* metres, int32_t* primitives, uint32_t& largest) {
  return path == Instructions::kAvx2 ? depthMetresMaskingAvx2(ids, window, n, rows, metres, primitives, largest)
                                     : depthMetresMaskingAvx512(ids, window, n, rows, metres, primitives, largest);
}

size_t windowDepth(Instructions path, const uint32_t* ids, const float* metres, size_t n, const DepthRows& rows,
                   float* window, uint32_t* good, uint32_t* bad) {
  return path == Instructions::kAvx2 ? windowDepthAvx2(ids, metres, n, rows, window, good, bad)
                                     : windowDepthAvx512(ids, metres, n, rows, window, good, bad);
}
size_t encodeViper(Instructions, const uint8_t* class_ids, const int32_t* instance_ids, size_t n, uint8_t* rgb) {
  return encodeViperAvx2(class_ids, instance_ids, n, rgb);
}
#else
// Never called: kernelPath is kScalar.
size_t colorize(Instructions, const uint8_t*, size_t, const uint32_t*, uint8_t*) { return 0; }
size_t overlay(Instructions, const uint8_t*, const uint8_t*, size_t, const uint32_t*, int, uint8_t*) { return 0; }
size_t depthMetres(Instructions, const uint32_t*, const float*, size_t, const DepthRows&, float*) { return 0; }
size_t depthMetresMasking(Instructions, const uint32_t*, const float*, size_t, const DepthRows&, float*, int32_t*,
                          uint32_t&) {
  return 0;
}
size_t windowDepth(Instructions, const uint32_t*, const float*, size_t, const DepthRows&, float*, uint32_t*,
                   uint32_t*) {
  return 0;
}
size_t encodeViper(Instructions, const uint8_t*, const int32_t*, size_t, uint8_t*) { return 0; }
#endif

}  // namespace pixel_kernels
}  // namespace viper
