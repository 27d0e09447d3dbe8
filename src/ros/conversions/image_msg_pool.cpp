#include "viper/ros/conversions/image_msg_pool.h"

#include "viper/ros/conversions/image_conversions.h"

#include <boost/make_shared.hpp>

namespace viper {

sensor_msgs::ImagePtr ImageMsgPool::take(const std_msgs::Header& header, uint32_t width, uint32_t height,
                                         const std::string& encoding, uint32_t bytes_per_pixel) {
  const size_t bytes = static_cast<size_t>(width) * height * bytes_per_pixel;
  // use_count() 1: nobody but the pool holds it, and nobody can take it from the pool but us.
  sensor_msgs::ImagePtr* other_size = nullptr;
  for (sensor_msgs::ImagePtr& m : held_) {
    if (m.use_count() != 1) continue;
    if (m->data.size() == bytes) {
      shapeImageMsg(header, width, height, encoding, bytes_per_pixel, *m);  // no resize: nothing zeroed
      return m;
    }
    other_size = &m;
  }
  return hold(newImageMsgPtr(header, width, height, encoding, bytes_per_pixel), other_size);
}

sensor_msgs::ImagePtr ImageMsgPool::takeBytes(size_t bytes) {
  sensor_msgs::ImagePtr* other_size = nullptr;
  for (sensor_msgs::ImagePtr& m : held_) {
    if (m.use_count() != 1) continue;
    if (m->data.size() == bytes) return m;
    other_size = &m;
  }
  return hold(boost::make_shared<sensor_msgs::Image>(), other_size);
}

sensor_msgs::ImagePtr ImageMsgPool::hold(sensor_msgs::ImagePtr m, sensor_msgs::ImagePtr* other_size) {
  if (held_.size() < capacity_) held_.push_back(m);
  else if (other_size) *other_size = m;
  return m;
}

}  // namespace viper
