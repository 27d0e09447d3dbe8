// Checks and conversions of the evaluate node's own inputs: instance predictions and sparse flow
// (images and poses: include/viper/ros/conversions/). Each check returns "" when the input is
// fine, or what is wrong with it (for a throttled error that names the topic).
#pragma once

#include "viper/evaluation/evaluation.h"
#include "viper/evaluation/instance_metrics.h"
#include "viper/ros/conversions/image_conversions.h"  // checkImage
#include "viper/ros/conversions/pose_conversions.h"   // poseFromOdometry

#include <opencv_apps/FlowArrayStamped.h>
#include <sensor_msgs/Image.h>
#include <viper/InstancePredictionArray.h>

#include <string>
#include <vector>

namespace viper {

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

}  // namespace viper
