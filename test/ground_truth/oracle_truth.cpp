#include "oracle_truth.h"

#include "viper/capture/capture_stream.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <stdexcept>

namespace viper {
namespace truth {

const std::vector<Sequence>& sequences() {
  static const std::vector<Sequence> all = [] {
    std::vector<Sequence> out;
    for (const char* condition : {"day", "sunset", "rain", "snow", "night"}) {
      Sequence s;
      s.condition = condition;
      const std::string base = std::string(VIPER_FLOW_TRUTH_DIR) + "/world_" + condition;
      CaptureReader reader(base + ".vcap");
      CaptureFrame f;
      while (reader.next(f) == CaptureReader::Status::kFrame) s.frames.push_back(f);
      s.oracle = readOracle(base + ".oracle");
      out.push_back(std::move(s));
    }
    for (Sequence& s : out) {
      std::map<uint64_t, const OracleFrame*> by_number;
      for (const OracleFrame& o : s.oracle.frames) by_number[o.number] = &o;
      for (const CaptureFrame& f : s.frames) {
        const auto it = by_number.find(f.number);
        if (it == by_number.end())
          throw std::runtime_error(s.condition + ": frame " + std::to_string(f.number) + " is not in the oracle");
        s.truth.push_back(it->second);
      }
    }
    return out;
  }();
  return all;
}

bool isEffect(const OracleDraw& d) {
  return d.mesh == "sky_dome" || d.mesh == "rain_streaks" || d.mesh == "snow_flakes" || d.mesh == "sun_glare";
}

Eigen::Vector3d worldVertex(const OracleDraw& d, const OracleMesh& m, uint32_t v) {
  const Eigen::Vector4d p(m.positions_xyz[3 * v], m.positions_xyz[3 * v + 1], m.positions_xyz[3 * v + 2], 1.0);
  Eigen::Vector4d posed = p;
  if (d.skinned) {
    Eigen::Matrix4d skin = Eigen::Matrix4d::Zero();
    for (int k = 0; k < 4; ++k)
      skin += static_cast<double>(m.bone_weights[4 * v + k]) * d.bones.at(m.bone_ids[4 * v + k]).cast<double>();
    posed = skin * p;
  }
  return (d.world.cast<double>() * posed).head<3>();
}

std::array<Eigen::Vector3d, 3> worldTriangle(const OracleDraw& d, const OracleMesh& m, uint32_t t) {
  return {worldVertex(d, m, m.indices[3 * t]), worldVertex(d, m, m.indices[3 * t + 1]),
          worldVertex(d, m, m.indices[3 * t + 2])};
}

Ray pixelRay(const OracleFrame& f, uint32_t width, uint32_t height, int x, int y) {
  const Eigen::Matrix4d inv = (f.projection.cast<double>() * f.view.cast<double>()).inverse();
  const double ndc_x = 2.0 * (x + 0.5) / width - 1.0, ndc_y = 1.0 - 2.0 * (y + 0.5) / height;
  const Eigen::Vector4d near = inv * Eigen::Vector4d(ndc_x, ndc_y, -1.0, 1.0);
  const Eigen::Vector4d far = inv * Eigen::Vector4d(ndc_x, ndc_y, 1.0, 1.0);
  Ray r;
  r.origin = near.head<3>() / near.w();
  r.direction = (far.head<3>() / far.w() - r.origin).normalized();
  return r;
}

std::optional<Hit> intersect(const Ray& ray, const std::array<Eigen::Vector3d, 3>& tri) {
  // Moeller-Trumbore, without rejecting points outside the triangle (the caller judges them).
  const Eigen::Vector3d e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
  const Eigen::Vector3d p = ray.direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return std::nullopt;
  const Eigen::Vector3d s = ray.origin - tri[0];
  const double u = s.dot(p) / det;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = ray.direction.dot(q) / det;
  Hit h;
  h.distance = e2.dot(q) / det;
  h.barycentric = Eigen::Vector3d(1.0 - u - v, u, v);
  return h;
}

std::optional<Projected> project(const OracleFrame& f, uint32_t width, uint32_t height, const Eigen::Vector3d& p) {
  const Eigen::Vector4d camera = f.view.cast<double>() * p.homogeneous();
  const Eigen::Vector4d clip = f.projection.cast<double>() * camera;
  if (!(clip.w() > 0.0)) return std::nullopt;
  Projected out;
  out.pixel = Eigen::Vector2d((clip.x() / clip.w() + 1.0) * 0.5 * width - 0.5,
                              (1.0 - clip.y() / clip.w()) * 0.5 * height - 0.5);
  out.depth_m = -camera.z();
  return out;
}

std::map<std::pair<uint32_t, std::string>, uint32_t> drawsByPart(const OracleFrame& f) {
  std::map<std::pair<uint32_t, std::string>, uint32_t> out;
  for (const OracleDraw& d : f.draws)
    if (!out.emplace(std::make_pair(d.object_id, d.part), d.index).second)
      throw std::runtime_error("oracle frame " + std::to_string(f.number) + ": object " + std::to_string(d.object_id) +
                               " has two parts called " + d.part);
  return out;
}

}  // namespace truth
}  // namespace viper
