#include "viper/dataset/kitti_labels.h"

#include <cmath>
#include <cstdio>

namespace viper::dataset {
namespace {

double wrapAngle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a < -M_PI) a += 2 * M_PI;
  return a;
}

}  // namespace

std::string kittiTypeOfViperClass(int viper_class_id) {
  switch (viper_class_id) {
    case 24: return "Car";
    case 25: return "Van";
    case 26:  // bus: KITTI has no bus class and labels buses Truck
    case 27: return "Truck";
    case 20: return "Pedestrian";
    case 22:  // bicycle
    case 23: return "Cyclist";  // motorcycle
    case 29: return "Tram";     // train
    case 28: return "Misc";     // trailer
    default: return "DontCare";
  }
}

KittiObject kittiObjectOfBox(const Eigen::Vector3d& center, const Eigen::Quaterniond& orientation,
                             const Eigen::Vector3d& size) {
  const Eigen::Matrix3d axes = orientation.normalized().toRotationMatrix();  // columns: object axes in the camera frame
  int up = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(axes(1, k)) > std::abs(axes(1, up))) up = k;
  const int a = (up + 1) % 3, b = (up + 2) % 3;
  const int along = size[a] >= size[b] ? a : b, across = along == a ? b : a;
  KittiObject o;
  o.height = size[up];
  o.length = size[along];
  o.width = size[across];
  o.location = center + Eigen::Vector3d(0.0, o.height / 2, 0.0);
  const Eigen::Vector3d heading = axes.col(along);
  o.rotation_y = wrapAngle(std::atan2(-heading.z(), heading.x()));
  o.alpha = wrapAngle(o.rotation_y - std::atan2(center.x(), center.z()));
  return o;
}

std::string kittiLabelLine(const KittiObject& o) {
  char line[512];
  std::snprintf(line, sizeof line, "%s %.2f %d %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f",
                o.type.c_str(), o.truncated, o.occluded, o.alpha, o.box[0], o.box[1], o.box[2], o.box[3], o.height,
                o.width, o.length, o.location.x(), o.location.y(), o.location.z(), o.rotation_y);
  return line;
}

std::string kittiTrackingLine(uint32_t frame, int64_t track_id, const KittiObject& object) {
  return std::to_string(frame) + " " + std::to_string(track_id) + " " + kittiLabelLine(object);
}

std::string kittiCalibText(const Eigen::Matrix<double, 3, 4>& P) {
  std::string out;
  auto row = [&](const std::string& name, const double* values, int n) {
    out += name + ":";
    char v[32];
    for (int i = 0; i < n; ++i) {
      std::snprintf(v, sizeof v, " %.12e", values[i]);
      out += v;
    }
    out += "\n";
  };
  double p[12];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) p[r * 4 + c] = P(r, c);
  for (const char* name : {"P0", "P1", "P2", "P3"}) row(name, p, 12);
  const double identity3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double identity34[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  row("R0_rect", identity3, 9);
  row("Tr_velo_to_cam", identity34, 12);
  row("Tr_imu_to_velo", identity34, 12);
  return out;
}

}  // namespace viper::dataset
