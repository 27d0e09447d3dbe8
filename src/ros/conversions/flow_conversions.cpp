#include "viper/ros/conversions/flow_conversions.h"

#include "viper/ros/conversions/image_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <stdexcept>

namespace viper {

FlowMessages toFlowMsgs(const FlowField& field, const std_msgs::Header& header) {
  const size_t n = static_cast<size_t>(field.width) * field.height;
  if (field.uv.size() != 2 * n || field.visible.size() != n)
    throw std::invalid_argument("flow field of " + std::to_string(field.width) + "x" + std::to_string(field.height) +
                                " holds " + std::to_string(field.uv.size()) + " flow values and " +
                                std::to_string(field.visible.size()) + " mask values");
  FlowMessages m;
  m.flow = imageMsgPtr(header, field.width, field.height, sensor_msgs::image_encodings::TYPE_32FC2, 8, field.uv.data());
  m.visible = imageMsgPtr(header, field.width, field.height, sensor_msgs::image_encodings::MONO8, 1,
                          field.visible.data());
  return m;
}

void shapeFlowMsgs(uint32_t width, uint32_t height, const std_msgs::Header& header, sensor_msgs::Image& flow,
                   sensor_msgs::Image& visible) {
  shapeImageMsg(header, width, height, sensor_msgs::image_encodings::TYPE_32FC2, 8, flow);
  shapeImageMsg(header, width, height, sensor_msgs::image_encodings::MONO8, 1, visible);
}

std::string flowFieldFromMsgs(const sensor_msgs::Image& flow, const sensor_msgs::Image& visible, FlowField& field) {
  std::string problem = checkImage(flow, sensor_msgs::image_encodings::TYPE_32FC2);
  if (!problem.empty()) return "flow: " + problem;
  problem = checkImage(visible, sensor_msgs::image_encodings::MONO8, flow.width, flow.height);
  if (!problem.empty()) return "visible: " + problem;
  const size_t n = static_cast<size_t>(flow.width) * flow.height;
  field.width = flow.width, field.height = flow.height;
  const auto* uv = reinterpret_cast<const float*>(flow.data.data());
  field.uv.assign(uv, uv + 2 * n);
  field.visible.assign(visible.data.begin(), visible.data.end());
  return "";
}

sensor_msgs::Image toFlowMsg(const dataset::FlowImage& flow, const std_msgs::Header& header) {
  return imageMsg(header, flow.width, flow.height, sensor_msgs::image_encodings::TYPE_32FC2, 8, flow.uv.data());
}

std::string flowFromMsg(const sensor_msgs::Image& msg, dataset::FlowImage& out) {
  const std::string problem = checkImage(msg, sensor_msgs::image_encodings::TYPE_32FC2, 0, 0, ImageLayout::kAnyStep);
  if (!problem.empty()) return problem;
  out.width = msg.width, out.height = msg.height;
  out.uv.resize(2 * out.pixels());
  copyImageRows(msg, 4, reinterpret_cast<uint8_t*>(out.uv.data()));
  return "";
}

}  // namespace viper
