#include "viper/ground_truth/ego_motion.h"

#include "viper/ground_truth/camera_model.h"

#include <stdexcept>
#include <string>

namespace viper {

Eigen::Isometry3d bodyFromOptical() {
  Eigen::Matrix3d r;
  // Columns: the optical axes (x right, y down, z forward) written in body axes (x fwd, y left, z up).
  r << 0, 0, 1,
      -1, 0, 0,
       0, -1, 0;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = r;
  return t;
}

EgoPose egoPoseFromView(const GlMatrix& view, double time_s) {
  if (!view.allFinite()) throw std::invalid_argument("view matrix is not finite");
  const Eigen::Matrix3d r = view.topLeftCorner<3, 3>().cast<double>();
  const double ortho_error = (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (ortho_error > 1e-4 || r.determinant() < 0 || view.row(3) != Eigen::RowVector4f(0, 0, 0, 1))
    throw std::invalid_argument("view matrix is not rigid (rotation off by " + std::to_string(ortho_error) +
                                ", or projective last row)");
  EgoPose pose;
  pose.time_s = time_s;
  pose.map_from_body = opticalFromWorld(view).inverse() * bodyFromOptical().inverse();
  return pose;
}

BodyTwist bodyTwist(const EgoPose& a, const EgoPose& b) {
  const double dt = b.time_s - a.time_s;
  if (!(dt > 0)) throw std::invalid_argument("bodyTwist: time must increase");
  const Eigen::Isometry3d delta = b.map_from_body.inverse() * a.map_from_body;  // a's body in b's body
  BodyTwist t;
  t.linear_mps = -delta.translation() / dt;
  const Eigen::AngleAxisd aa(delta.linear().transpose());  // rotation from a to b, in b's frame
  t.angular_radps = aa.axis() * aa.angle() / dt;
  return t;
}

}  // namespace viper
