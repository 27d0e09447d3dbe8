// ImageMsgPool: a message is taken again only after everyone else let go of it, shaped anew; one
// still held is never handed out twice; the pool keeps at most its capacity.
#include "viper/ros/conversions/image_msg_pool.h"

#include "sample_header.h"

#include <gtest/gtest.h>

namespace viper {
namespace {

TEST(ImageMsgPool, RecyclesOnlyMessagesNobodyElseHolds) {
  ImageMsgPool pool(2);
  const std_msgs::Header h = test::sampleHeader();
  sensor_msgs::ImagePtr a = pool.take(h, 4, 3, "32FC2", 8);
  EXPECT_EQ(a->data.size(), 96u);
  EXPECT_EQ(a->step, 32u);
  EXPECT_EQ(a->encoding, "32FC2");
  EXPECT_EQ(a->header.frame_id, "camera_optical");
  const sensor_msgs::Image* first = a.get();
  sensor_msgs::ImagePtr b = pool.take(h, 4, 3, "32FC2", 8);
  EXPECT_NE(b.get(), first) << "a is still held";
  sensor_msgs::ImageConstPtr subscriber = a;  // a subscriber still holds it after the publisher let go
  a.reset();
  sensor_msgs::ImagePtr c = pool.take(h, 4, 3, "32FC2", 8);
  EXPECT_NE(c.get(), first);
  EXPECT_NE(c.get(), b.get());
  subscriber.reset();
  std_msgs::Header later = h;
  later.stamp = ros::Time(13, 0);
  sensor_msgs::ImagePtr d = pool.take(later, 4, 3, "32FC2", 8);
  EXPECT_EQ(d.get(), first) << "nobody holds it any more";
  EXPECT_EQ(d->header.stamp, later.stamp);
  // One of the same byte size is reshaped; another size is a new message.
  d.reset();
  sensor_msgs::ImagePtr f = pool.take(h, 2, 3, "32SC1", 16);
  EXPECT_EQ(f.get(), first);
  EXPECT_EQ(f->width, 2u);
  EXPECT_EQ(f->step, 32u);
  EXPECT_EQ(f->encoding, "32SC1");
  f.reset();
  sensor_msgs::ImagePtr e = pool.take(h, 8, 3, "mono8", 1);
  EXPECT_EQ(e->data.size(), 24u);
  EXPECT_EQ(e->encoding, "mono8");
  EXPECT_NE(static_cast<const void*>(e->data.data()), static_cast<const void*>(b->data.data()));
}

}  // namespace
}  // namespace viper
