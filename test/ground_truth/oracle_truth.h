// Analytic truth from a world's oracle (version 2: meshes, matrices, bones), computed without any
// of the capture's derived data, and the captured sequences of the five conditions it is compared
// with (made at build time by cmake/ground_truth.cmake).
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/oracle.h"

#include <Eigen/Core>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace viper {
namespace truth {

/// One captured sequence of the world and its oracle; frames[i] was rendered as oracle frame
/// truth[i].
struct Sequence {
  std::string condition;
  std::vector<CaptureFrame> frames;
  Oracle oracle;
  std::vector<const OracleFrame*> truth;
};

/// The world in day, sunset, rain, snow and night (VIPER_FLOW_TRUTH_DIR/world_<condition>.vcap and
/// .oracle), read once. Throws std::runtime_error if a file is missing or a frame is not in its
/// oracle.
const std::vector<Sequence>& sequences();

/// Draws whose vertex shader makes geometry the oracle does not describe: the sky dome (projected
/// onto the far plane), rain and snow particles (billboards moved in the shader) and the sun glare
/// sprite (no depth). Their pixels have no analytic truth.
bool isEffect(const OracleDraw& draw);

/// Vertex `v` of `mesh` as drawn by `draw`, in world coordinates (metres): world * p for rigid
/// draws, world * sum_k w_k bones[id_k] * p for skinned ones; computed in double from the floats.
Eigen::Vector3d worldVertex(const OracleDraw& draw, const OracleMesh& mesh, uint32_t v);

/// The three world-space corners of triangle `t` of `mesh` as drawn by `draw`.
std::array<Eigen::Vector3d, 3> worldTriangle(const OracleDraw& draw, const OracleMesh& mesh, uint32_t t);

/// The viewing ray through the centre of pixel (x, y) (top row 0) of a width x height image
/// rendered with `view` and `projection`: origin on the near plane, unit direction, world frame.
struct Ray {
  Eigen::Vector3d origin, direction;
};
Ray pixelRay(const OracleFrame& frame, uint32_t width, uint32_t height, int x, int y);

/// Barycentric coordinates (b0, b1, b2) of the point where `ray` meets the plane of `tri`, and the
/// distance along the ray; nullopt if the ray is parallel to the plane.
struct Hit {
  Eigen::Vector3d barycentric;
  double distance = 0.0;
};
std::optional<Hit> intersect(const Ray& ray, const std::array<Eigen::Vector3d, 3>& tri);

/// Projection of a world point with a frame's oracle camera: pixel coordinates with pixel centres
/// at integers (u right, v down, as FlowField) and the depth along the optical axis (metres);
/// nullopt if the point is not in front of the camera.
struct Projected {
  Eigen::Vector2d pixel;
  double depth_m = 0.0;
};
std::optional<Projected> project(const OracleFrame& frame, uint32_t width, uint32_t height, const Eigen::Vector3d& p);

/// Index of each (object id, part) among a frame's draws. Throws std::runtime_error if a pair
/// occurs twice.
std::map<std::pair<uint32_t, std::string>, uint32_t> drawsByPart(const OracleFrame& frame);

}  // namespace truth
}  // namespace viper
