#include "viper/ros/evaluation/evaluate_inputs.h"

#include <cmath>

namespace viper {

size_t evaluateBytesPerPixel(const std::string& encoding) {
  if (encoding == "mono8") return 1;
  if (encoding == "32SC1") return 4;
  if (encoding == "32FC2") return 8;
  return 0;
}

std::string checkImage(const sensor_msgs::Image& image, const std::string& encoding, uint32_t width,
                       uint32_t height) {
  const std::string size = std::to_string(image.width) + "x" + std::to_string(image.height);
  if (image.encoding != encoding) return "encoding '" + image.encoding + "' (" + size + "), expected '" + encoding + "'";
  const size_t bpp = evaluateBytesPerPixel(encoding);
  if (image.width == 0 || image.height == 0) return "empty image (" + size + ")";
  if (width != 0 && (image.width != width || image.height != height))
    return "size " + size + ", expected " + std::to_string(width) + "x" + std::to_string(height);
  if (bpp > 1 && image.is_bigendian) return "big-endian " + encoding + " data is not supported";
  if (image.step != image.width * bpp)
    return "step " + std::to_string(image.step) + " for " + size + " " + encoding + ", expected " +
           std::to_string(image.width * bpp) + " (rows must not be padded)";
  if (image.data.size() != static_cast<size_t>(image.step) * image.height)
    return std::to_string(image.data.size()) + " data bytes for " + size + " " + encoding + ", expected " +
           std::to_string(static_cast<size_t>(image.step) * image.height);
  return "";
}

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

std::string poseFromOdometry(const nav_msgs::Odometry& msg, Eigen::Isometry3d& pose) {
  const auto& p = msg.pose.pose.position;
  const auto& q = msg.pose.pose.orientation;
  const Eigen::Vector3d t(p.x, p.y, p.z);
  const Eigen::Quaterniond r(q.w, q.x, q.y, q.z);
  if (!t.allFinite() || !r.coeffs().allFinite()) return "non-finite pose";
  if (std::abs(r.norm() - 1.0) > 1e-3)
    return "orientation quaternion has norm " + std::to_string(r.norm()) + ", expected 1";
  pose = Eigen::Isometry3d::Identity();
  pose.linear() = r.normalized().toRotationMatrix();
  pose.translation() = t;
  return "";
}

}  // namespace viper
