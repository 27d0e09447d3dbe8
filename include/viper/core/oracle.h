// Oracle files: the true answers a test world writes next to its rendering (object ids, classes,
// parts, matrices, bones of every draw call). For tests only: no capture layer or ground-truth node
// may read them. Format: docs/oracle_format.md.
#pragma once

#include "viper/core/capture_frame.h"

#include <Eigen/Core>

#include <cstdint>
#include <fstream>
#include <iosfwd>
#include <string>
#include <vector>

namespace viper {

/// One draw call as the world issued it.
struct OracleDraw {
  /// Index of the draw call within its frame, in issue order (0, 1, 2, ...).
  uint32_t index = 0;
  /// Object the draw belongs to; stable over a sequence and shared by all parts of one object.
  /// 0 is a valid id (no special meaning).
  uint32_t object_id = 0;
  /// VIPER class id (0..31, see config/viper_classes.csv).
  uint32_t class_id = 0;
  /// Name of the part within its object (e.g. "body", "wheel_fl"); no whitespace, not empty.
  std::string part;
  /// Name of the mesh (vertex/index buffer contents); equal names mean equal buffer contents.
  std::string mesh;
  /// Model -> world matrix exactly as passed to glUniformMatrix4fv (column-major, world Z up).
  GlMatrix world = GlMatrix::Identity();
  /// True if the vertex shader deformed the mesh with `bones`.
  bool skinned = false;
  /// Bone matrices as passed to the shader (mesh coordinates -> deformed mesh coordinates);
  /// a deformed position is sum_i weight_i * bones[bone_id_i] * position. Empty unless skinned.
  std::vector<GlMatrix> bones;
};

/// One frame of a world's sequence.
struct OracleFrame {
  /// Frame number, counting buffer swaps from 0.
  uint64_t number = 0;
  /// Simulated time of the frame, seconds.
  double time_s = 0.0;
  /// World -> OpenGL camera matrix and projection exactly as passed to GL (column-major).
  GlMatrix view = GlMatrix::Identity();
  GlMatrix projection = GlMatrix::Identity();
  /// Pose of the camera body frame (REP 103: x forward, y left, z up) in the world (Z up).
  Eigen::Matrix4d map_from_camera_body = Eigen::Matrix4d::Identity();
  /// Draw calls in issue order; draws[i].index == i.
  std::vector<OracleDraw> draws;
};

/// A whole oracle file.
struct Oracle {
  /// Size of the rendered images, pixels.
  uint32_t width = 0;
  uint32_t height = 0;
  /// Frames in file order (numbers strictly increasing).
  std::vector<OracleFrame> frames;
};

/// Writes an oracle file frame by frame (each frame is flushed, so a run that dies leaves whole
/// frames behind).
class OracleWriter {
 public:
  /// Creates (truncates) `path` and writes the header. Throws std::runtime_error naming the file
  /// if it cannot be opened, std::invalid_argument if a size is zero.
  OracleWriter(const std::string& path, uint32_t width, uint32_t height);

  /// Appends one frame. Throws std::invalid_argument if the frame is inconsistent (draw indices not
  /// 0..n-1, a name empty or with whitespace, class id > 31, bones on a rigid draw or none on a
  /// skinned one, non-finite numbers, frame number not above the previous one), std::runtime_error
  /// naming the file on a write error.
  void write(const OracleFrame& frame);

 private:
  std::string path_;
  std::ofstream out_;
  bool has_previous_ = false;
  uint64_t previous_number_ = 0;
};

/// Checks one frame as OracleWriter::write does; returns an empty string if it is consistent,
/// else what is wrong.
std::string validateOracleFrame(const OracleFrame& frame);

/// Parses oracle text read from `in`; `source_name` names it in errors. Throws std::runtime_error
/// "<source_name>:<line>: <what is wrong>" on any malformed, inconsistent or truncated input.
Oracle parseOracle(std::istream& in, const std::string& source_name);

/// Reads an oracle file. Throws std::runtime_error naming the file (and line) if it cannot be
/// opened or is malformed.
Oracle readOracle(const std::string& path);

}  // namespace viper
