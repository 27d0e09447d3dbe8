// Checks and conversions of the evaluate node's inputs: images, instance predictions, sparse flow
// and poses. Each check returns "" when the input is fine, or what is wrong with it (for a
// throttled error that names the topic).
#pragma once

#include "viper/evaluation/evaluation.h"
#include "viper/evaluation/instance_metrics.h"

#include <nav_msgs/Odometry.h>
#include <opencv_apps/FlowArrayStamped.h>
#include <sensor_msgs/Image.h>
#include <viper/InstancePredictionArray.h>

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace viper {

/// Bytes per pixel of the encodings the evaluate node reads (mono8 1, 32SC1 4, 32FC2 8); 0 for
/// any other.
size_t evaluateBytesPerPixel(const std::string& encoding);

/// Checks that `image` has `encoding`, is little-endian where that matters, has unpadded rows
/// (step = width * bytes per pixel), as many bytes as its size says, and is width x height
/// (0 = any size, but not empty).
std::string checkImage(const sensor_msgs::Image& image, const std::string& encoding, uint32_t width = 0,
                       uint32_t height = 0);

/// The instances of `msg` for a width x height frame: each mask must be a mono8 image
/// (checkImage) lying inside the frame at its offset, with a finite score. The masks point into
/// `msg`, which must outlive `out`. On a problem, `out` is left empty.
std::string toBoxedInstances(const InstancePredictionArray& msg, uint32_t width, uint32_t height,
                             std::vector<BoxedInstance>& out);

/// Where the points of a sparse flow message lie: in the first frame of the pair
/// (opencv_apps fback_flow and simple_flow: point = x_f, velocity = x_f+1 - x_f) or in the second
/// (opencv_apps lk_flow: point = x_f+1, velocity = x_f+1 - x_f).
enum class SparsePoints { kFirstFrame, kSecondFrame };

/// The vectors of an opencv_apps flow message, with points moved into the first frame.
std::vector<SparseFlowVector> fromFlowArray(const opencv_apps::FlowArrayStamped& msg, SparsePoints points);

/// The pose of an odometry message (pose.pose: child frame in the parent frame). Returns "" or
/// what is wrong (non-finite values, a quaternion far from unit length).
std::string poseFromOdometry(const nav_msgs::Odometry& msg, Eigen::Isometry3d& pose);

}  // namespace viper
