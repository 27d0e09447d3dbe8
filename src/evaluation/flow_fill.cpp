#include "viper/evaluation/flow_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viper {
namespace {

bool isValid(const float* v) { return std::isfinite(v[0]) && std::isfinite(v[1]); }
void assign(float* to, const float* from) { to[0] = from[0], to[1] = from[1]; }

// A line of n vectors (`at(i)`: the i-th): those before its first valid vector take that one, those
// after its last valid vector take that one. A line without any stays as it is.
template <class At>
void extendEnds(uint32_t n, At at) {
  uint32_t first = 0;
  while (first < n && !isValid(at(first))) ++first;
  if (first == n) return;
  for (uint32_t i = 0; i < first; ++i) assign(at(i), at(first));
  uint32_t last = n - 1;
  while (!isValid(at(last))) --last;
  for (uint32_t i = last + 1; i < n; ++i) assign(at(i), at(last));
}

}  // namespace

// The steps of the KITTI devkit's FlowImage::interpolateBackground (io_flow.h): per row, inner
// gaps take the per-component minimum of their two neighbours, then the row's ends copy its first
// and last vector; per column, the ends copy its first and last vector.
void fillMissingFlow(float* uv, uint32_t width, uint32_t height) {
  if (uv == nullptr && width > 0 && height > 0) throw std::invalid_argument("fillMissingFlow: null flow image");
  auto at = [&](uint32_t x, uint32_t y) { return uv + 2 * (static_cast<size_t>(y) * width + x); };
  for (uint32_t y = 0; y < height; ++y) {
    uint32_t gap = 0;  // invalid vectors just before x
    for (uint32_t x = 0; x < width; ++x) {
      if (!isValid(at(x, y))) {
        ++gap;
        continue;
      }
      if (gap > 0 && x > gap) {  // a gap with a valid vector on both sides
        const float* left = at(x - gap - 1, y);
        const float* right = at(x, y);
        const float fill[2] = {std::min(left[0], right[0]), std::min(left[1], right[1])};
        for (uint32_t g = x - gap; g < x; ++g) assign(at(g, y), fill);
      }
      gap = 0;
    }
    extendEnds(width, [&](uint32_t x) { return at(x, y); });
  }
  for (uint32_t x = 0; x < width; ++x) extendEnds(height, [&](uint32_t y) { return at(x, y); });
}

}  // namespace viper
