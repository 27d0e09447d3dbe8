#include "viper/ros/evaluation/evaluate_inputs.h"

#include <cmath>

namespace viper {

std::string toBoxedInstances(const InstancePredictionArray& msg, uint32_t width, uint32_t height,
                             std::vector<BoxedInstance>& out) {
  out.clear();
  std::vector<BoxedInstance> result(msg.instances.size());
  for (size_t i = 0; i < msg.instances.size(); ++i) {
    const InstancePrediction& p = msg.instances[i];
    const std::string name = "instance " + std::to_string(i);
    const std::string problem = checkImage(p.mask, "mono8");
    if (!problem.empty()) return name + " mask: " + problem;
    if (static_cast<uint64_t>(p.x_offset) + p.mask.width > width ||
        static_cast<uint64_t>(p.y_offset) + p.mask.height > height)
      return name + " mask " + std::to_string(p.mask.width) + "x" + std::to_string(p.mask.height) + " at (" +
             std::to_string(p.x_offset) + ", " + std::to_string(p.y_offset) + ") leaves the " + std::to_string(width) +
             "x" + std::to_string(height) + " frame";
    if (!std::isfinite(p.score)) return name + " has a non-finite score";
    BoxedInstance& b = result[i];
    b.class_id = p.class_id;
    b.score = p.score;
    b.x0 = p.x_offset, b.y0 = p.y_offset;
    b.width = p.mask.width, b.height = p.mask.height;
    b.mask = p.mask.data.data();
  }
  out = std::move(result);
  return "";
}

std::vector<SparseFlowVector> fromFlowArray(const opencv_apps::FlowArrayStamped& msg, SparsePoints points) {
  std::vector<SparseFlowVector> out;
  out.reserve(msg.flow.size());
  for (const opencv_apps::Flow& f : msg.flow) {
    SparseFlowVector v;
    v.u = f.velocity.x, v.v = f.velocity.y;
    v.x = f.point.x, v.y = f.point.y;
    if (points == SparsePoints::kSecondFrame) v.x -= v.u, v.y -= v.v;
    out.push_back(v);
  }
  return out;
}

}  // namespace viper
