#include "viper/ground_truth/labelled_cloud.h"

#include "rigid_flow_case.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>

namespace viper {
namespace {

using namespace test;

// The rigid case's square, its depth exact, with colour, class and instance images made up per pixel.
struct CloudCase {
  RigidCase c;
  std::vector<uint8_t> rgb, classes;
  std::vector<int32_t> instances;
  PinholeIntrinsics k = intrinsicsFromGlProjection(c.proj, c.w, kH);
  CloudCase() {
    const size_t n = c.a.pixelCount();
    rgb.resize(3 * n), classes.resize(n), instances.resize(n);
    for (size_t p = 0; p < n; ++p) {
      rgb[3 * p] = uint8_t(p), rgb[3 * p + 1] = uint8_t(p / 7), rgb[3 * p + 2] = uint8_t(255 - p % 251);
      classes[p] = uint8_t(p % 32), instances[p] = int32_t(p % 5) - 1;  // -1 and 0 are no instance
    }
  }
  CloudImages images() const { return {c.w, kH, c.metres_a.data(), rgb.data(), classes.data(), instances.data()}; }
};

TEST(LabelledCloud, PointsLieOnTheSquareAndProjectBackToTheirPixels) {
  CloudCase k;
  std::vector<CloudPoint> cloud(cloudSize(k.c.w, kH, 1).points());
  ASSERT_EQ(cloud.size(), k.c.a.pixelCount());
  const size_t n = labelledCloud(k.images(), k.k, 1, cloud.data());
  size_t square = 0;
  for (uint32_t id : k.c.a.draw_ids) square += id != 0;
  ASSERT_GT(square, 500u);
  EXPECT_EQ(n, square);
  // The square's plane in camera a's optical frame.
  const Eigen::Isometry3d optical_from_world = opticalFromWorld(k.c.view_a);
  const Eigen::Affine3d placed(k.c.world_a.cast<double>());
  const Eigen::Vector3d normal = optical_from_world.linear() * placed.linear().col(2).normalized();
  const Eigen::Vector3d centre = optical_from_world * placed.translation();
  double worst_plane = 0, worst_pixel = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(k.c.w); ++x) {
      const size_t p = y * k.c.w + x;
      const CloudPoint& q = cloud[p];
      const Eigen::Vector3d point(q.x, q.y, q.z);
      EXPECT_EQ(point.allFinite(), k.c.a.draw_ids[p] != 0) << x << "," << y;
      uint32_t rgb;
      std::memcpy(&rgb, &q.rgb, 4);
      EXPECT_EQ(rgb, (uint32_t{k.rgb[3 * p]} << 16) | (uint32_t{k.rgb[3 * p + 1]} << 8) | k.rgb[3 * p + 2]);
      EXPECT_EQ(q.label, k.classes[p]);
      EXPECT_EQ(q.instance, uint32_t(std::max(k.instances[p], 0)));
      if (!point.allFinite()) continue;
      worst_plane = std::max(worst_plane, std::abs(normal.dot(point - centre)));
      worst_pixel = std::max(worst_pixel, (k.k.project(point) - Eigen::Vector2d(x, y)).norm());
    }
  EXPECT_LT(worst_plane, 1e-5) << "metres off the square's plane (depth ~6 m)";
  EXPECT_LT(worst_pixel, 1e-4) << "pixels between a point's projection and its pixel";
}

TEST(LabelledCloud, DecimationTakesEveryKthPixelOfEachRowAndColumn) {
  CloudCase k;
  std::vector<CloudPoint> full(cloudSize(k.c.w, kH, 1).points());
  labelledCloud(k.images(), k.k, 1, full.data());
  for (int d : {2, 3, 5, 7}) {
    const CloudSize size = cloudSize(k.c.w, kH, d);
    EXPECT_EQ(size.width, (k.c.w + d - 1) / d);
    EXPECT_EQ(size.height, (kH + d - 1) / d);
    std::vector<CloudPoint> cloud(size.points());
    labelledCloud(k.images(), k.k, d, cloud.data());
    for (uint32_t r = 0; r < size.height; ++r)
      for (uint32_t c = 0; c < size.width; ++c)
        ASSERT_EQ(std::memcmp(&cloud[r * size.width + c], &full[r * d * k.c.w + c * d], sizeof(CloudPoint)), 0)
            << "decimation " << d << " point " << c << "," << r;
  }
}

TEST(LabelledCloud, ImagesLeftOutGiveZeros) {
  CloudCase k;
  CloudImages images = k.images();
  images.rgb = nullptr, images.class_ids = nullptr, images.instance_ids = nullptr;
  std::vector<CloudPoint> cloud(k.c.a.pixelCount());
  EXPECT_GT(labelledCloud(images, k.k, 1, cloud.data()), 500u);
  for (const CloudPoint& q : cloud) EXPECT_TRUE(q.rgb == 0.0f && q.label == 0 && q.instance == 0);
}

TEST(LabelledCloud, BadInputThrows) {
  CloudCase k;
  std::vector<CloudPoint> cloud(k.c.a.pixelCount());
  EXPECT_THROW(labelledCloud(k.images(), k.k, 0, cloud.data()), std::invalid_argument);
  CloudImages no_depth = k.images();
  no_depth.depth_m = nullptr;
  EXPECT_THROW(labelledCloud(no_depth, k.k, 1, cloud.data()), std::invalid_argument);
  PinholeIntrinsics other = k.k;
  other.width += 1;
  EXPECT_THROW(labelledCloud(k.images(), other, 1, cloud.data()), std::invalid_argument);
  other = k.k;
  other.fx = 0;
  EXPECT_THROW(labelledCloud(k.images(), other, 1, cloud.data()), std::invalid_argument);
}

}  // namespace
}  // namespace viper
