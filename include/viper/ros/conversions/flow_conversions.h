// Optical flow: core flow types <-> 32FC2 flow images (u, v in pixels, NaN = undefined) and mono8
// visibility masks (255 = visible in the second frame). Part of the converter between messages and
// core types (include/viper/ros/conversions/; docs/design.md).
#pragma once

#include "viper/dataset/flow_image.h"
#include "viper/ground_truth/flow.h"

#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>

#include <string>

namespace viper {

/// A flow field as the flow node publishes it: the flow (32FC2) and its visibility mask (mono8).
struct FlowMessages {
  sensor_msgs::ImagePtr flow;
  sensor_msgs::ImagePtr visible;
};
/// The messages of `field` with `header`. Throws std::invalid_argument if its buffers do not hold
/// width x height pixels.
FlowMessages toFlowMsgs(const FlowField& field, const std_msgs::Header& header);
/// `flow` (32FC2) and `visible` (mono8) shaped as width x height images with `header`, their
/// buffers sized for computeFlow to write the flow into.
void shapeFlowMsgs(uint32_t width, uint32_t height, const std_msgs::Header& header, sensor_msgs::Image& flow,
                   sensor_msgs::Image& visible);
/// Back to a flow field: `flow` is 32FC2 and `visible` mono8 of the same size (packed rows).
/// Returns "" or what is wrong (naming which image), leaving `field` as it was.
std::string flowFieldFromMsgs(const sensor_msgs::Image& flow, const sensor_msgs::Image& visible, FlowField& field);

/// A flow image (the dataset's) as a 32FC2 message.
sensor_msgs::Image toFlowMsg(const dataset::FlowImage& flow, const std_msgs::Header& header);
/// A 32FC2 message into a flow image: any step, either byte order. Returns "" or what is wrong.
std::string flowFromMsg(const sensor_msgs::Image& msg, dataset::FlowImage& out);

}  // namespace viper
