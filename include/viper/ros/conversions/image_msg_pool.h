// Image messages recycled once every subscriber has let go of them. A nodelet that publishes a
// 1080p image a frame would otherwise have a new buffer zeroed (and, often, its pages faulted in
// fresh from the kernel) for every image, only to write every byte of it again. A published message
// is never changed: a message is taken again only when the pool holds the last reference to it
// (the nodelets beside it, their queues and synchronisers hold theirs until they are done; other
// processes get a copy serialised at publish time).
#pragma once

#include <sensor_msgs/Image.h>

#include <cstddef>
#include <string>
#include <vector>

namespace viper {

class ImageMsgPool {
 public:
  /// Keeps at most `capacity` messages (the most images of one kind in flight at once, as the
  /// pool has seen them; fewer only cost a fresh buffer). 16 was too few for the capture source at
  /// 8 frames in flight: the bridge's sink took fresh 8 MB buffers, whose pages the kernel zeroed
  /// on first touch (`clear_page_erms` 2.7-4.5 % of the manager in 3 of 4 profiles; 0.4-1.0 % with 32).
  /// Only the messages once in flight at the same time are kept.
  explicit ImageMsgPool(size_t capacity = 32) : capacity_(capacity) {}

  /// A message shaped as shapeImageMsg makes it (header, size, encoding, packed rows), whose
  /// pixels the caller writes, every byte: a recycled one of the same byte size, else a new one
  /// (zeroed).
  sensor_msgs::ImagePtr take(const std_msgs::Header& header, uint32_t width, uint32_t height,
                             const std::string& encoding, uint32_t bytes_per_pixel);
  /// A message for the caller to fill, fields and pixels: a recycled one whose pixels hold `bytes`
  /// bytes (as it was published: the caller overwrites every field), else a new, empty one.
  sensor_msgs::ImagePtr takeBytes(size_t bytes);

 private:
  // Keeps m while there is room, else in place of a free message of another size, if any.
  sensor_msgs::ImagePtr hold(sensor_msgs::ImagePtr m, sensor_msgs::ImagePtr* other_size);

  size_t capacity_;
  std::vector<sensor_msgs::ImagePtr> held_;
};

}  // namespace viper
