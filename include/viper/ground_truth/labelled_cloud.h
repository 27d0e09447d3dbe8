// Labelled point clouds (docs/ground_truth_nodes.md, "Labelled cloud"): a frame's depth lifted to
// 3D points in the optical frame, one per pixel (organised, optionally decimated), each with its
// colour, class id and instance id. The cloud node (src/ros/ground_truth/cloud_node.cpp) lays the
// points out as a sensor_msgs/PointCloud2 without another pass.
#pragma once

#include "viper/ground_truth/camera_model.h"

#include <cstddef>
#include <cstdint>

namespace viper {

/// One point, laid out as the cloud message carries it (24 bytes; PCL's PointXYZRGBL plus an
/// instance id): x, y, z in metres in the optical frame (REP 103: x right, y down, z forward; NaN
/// where the pixel has no depth), rgb as PCL packs it (the bits 0x00RRGGBB read as a float32),
/// label the class id, instance the instance (track) id, 0 for none.
struct CloudPoint {
  float x, y, z;
  float rgb;
  uint32_t label;
  uint32_t instance;
};
static_assert(sizeof(CloudPoint) == 24, "CloudPoint is the message's point layout");

/// A frame's images the cloud is made from, width*height values each, row-major, top row first.
/// Only `depth_m` is required; a null colour, class or instance image gives 0 in that field.
struct CloudImages {
  uint32_t width = 0, height = 0;
  const float* depth_m = nullptr;       ///< metres along the optical axis (REP 118), NaN = no surface
  const uint8_t* rgb = nullptr;         ///< rgb8: 3 bytes a pixel
  const uint8_t* class_ids = nullptr;   ///< class id per pixel
  const int32_t* instance_ids = nullptr;  ///< instance (track) id per pixel, 0 (or less) = none
};

/// The size of the cloud of a width x height image taking every `decimation`-th pixel in both
/// directions (pixels (0, 0), (k, 0), ...): ceil(width / k) x ceil(height / k).
struct CloudSize {
  uint32_t width = 0, height = 0;
  size_t points() const { return static_cast<size_t>(width) * height; }
};
/// Throws std::invalid_argument if `decimation` < 1.
CloudSize cloudSize(uint32_t width, uint32_t height, int decimation);

/// Lifts every `decimation`-th pixel (u, v) with depth z to the point z K^-1 (u, v, 1) of
/// `intrinsics` (pixel centres at integers, as PinholeIntrinsics), into `out` (cloudSize() points,
/// row-major: the organised cloud). Pixels without depth (not positive and finite) give NaN x, y, z
/// and keep their colour and ids. Returns the number of points with depth. Throws
/// std::invalid_argument if `decimation` < 1, `images.depth_m` is null, or the intrinsics' size is
/// not the images' or their focal lengths are not positive.
size_t labelledCloud(const CloudImages& images, const PinholeIntrinsics& intrinsics, int decimation, CloudPoint* out);

/// PCL's packing of an 8-bit colour into a float32 field named "rgb": the bits 0x00RRGGBB.
float packRgb(uint8_t r, uint8_t g, uint8_t b);

}  // namespace viper
