#include "viper/ground_truth/labelled_cloud.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace viper {

CloudSize cloudSize(uint32_t width, uint32_t height, int decimation) {
  if (decimation < 1) throw std::invalid_argument("cloud decimation " + std::to_string(decimation) + " is below 1");
  const uint32_t k = static_cast<uint32_t>(decimation);
  return {(width + k - 1) / k, (height + k - 1) / k};
}

float packRgb(uint8_t r, uint8_t g, uint8_t b) {
  const uint32_t bits = (uint32_t{r} << 16) | (uint32_t{g} << 8) | uint32_t{b};
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

size_t labelledCloud(const CloudImages& in, const PinholeIntrinsics& k, int decimation, CloudPoint* out) {
  const CloudSize size = cloudSize(in.width, in.height, decimation);
  if (!in.depth_m) throw std::invalid_argument("labelled cloud: no depth");
  if (k.width != in.width || k.height != in.height)
    throw std::invalid_argument("labelled cloud: camera of " + std::to_string(k.width) + "x" + std::to_string(k.height) +
                                " for images of " + std::to_string(in.width) + "x" + std::to_string(in.height));
  if (!(k.fx > 0.0) || !(k.fy > 0.0))
    throw std::invalid_argument("labelled cloud: focal lengths " + std::to_string(k.fx) + ", " + std::to_string(k.fy) +
                                " are not positive");
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  // x = (u - cx - skew * y) / fx and y = (v - cy) / fy on the plane z = 1, from K^-1.
  const double inv_fx = 1.0 / k.fx, inv_fy = 1.0 / k.fy;
  const size_t step = static_cast<size_t>(decimation);
  size_t with_depth = 0;
  for (uint32_t row = 0; row < size.height; ++row) {
    const size_t v = row * step;
    const double ray_y = (static_cast<double>(v) - k.cy) * inv_fy;
    const float ry = static_cast<float>(ray_y);
    CloudPoint* o = out + static_cast<size_t>(row) * size.width;
    for (uint32_t col = 0; col < size.width; ++col, ++o) {
      const size_t u = col * step, p = v * in.width + u;
      const float z = in.depth_m[p];
      if (z > 0.0f && z < inf) {
        const float rx = static_cast<float>((static_cast<double>(u) - k.cx - k.skew * ray_y) * inv_fx);
        o->x = rx * z, o->y = ry * z, o->z = z;
        ++with_depth;
      } else {
        o->x = o->y = o->z = nan;
      }
      o->rgb = in.rgb ? packRgb(in.rgb[3 * p], in.rgb[3 * p + 1], in.rgb[3 * p + 2]) : 0.0f;
      o->label = in.class_ids ? in.class_ids[p] : 0u;
      o->instance = in.instance_ids && in.instance_ids[p] > 0 ? static_cast<uint32_t>(in.instance_ids[p]) : 0u;
    }
  }
  return with_depth;
}

}  // namespace viper
