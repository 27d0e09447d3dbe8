// Oracle files: the true answers a test world writes next to its rendering (object ids, classes,
// parts, matrices, bones of every draw call, and the object-space geometry of every mesh drawn).
// For tests only: no capture layer or ground-truth node may read them. Format: docs/oracle_format.md.
#pragma once

#include "viper/capture/capture_frame.h"

#include <Eigen/Core>

#include <cstdint>
#include <fstream>
#include <iosfwd>
#include <map>
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

/// Object-space geometry of one mesh, exactly as the world uploaded it (version 2 files).
struct OracleMesh {
  /// Name the draws use (OracleDraw::mesh); no whitespace or '#', not empty.
  std::string name;
  /// x, y, z per vertex in the mesh's own coordinates (metres), the position buffer as uploaded.
  std::vector<float> positions_xyz;
  /// Triangle list: three vertex indices per triangle, in primitive (gl_PrimitiveID) order.
  std::vector<uint32_t> indices;
  /// Skinned meshes: 4 bone indices and 4 weights per vertex (a deformed vertex is
  /// sum_k weight_k * bones[bone_id_k] * position); both empty for rigid meshes.
  std::vector<uint32_t> bone_ids;
  std::vector<float> bone_weights;

  size_t vertexCount() const { return positions_xyz.size() / 3; }
  size_t triangleCount() const { return indices.size() / 3; }
  bool skinned() const { return !bone_ids.empty(); }
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
  /// Format version the file declared (1: no meshes; 2: meshes).
  int version = 0;
  /// Size of the rendered images, pixels.
  uint32_t width = 0;
  uint32_t height = 0;
  /// Frames in file order (numbers strictly increasing).
  std::vector<OracleFrame> frames;
  /// Meshes by name (version 2: every mesh any draw uses; empty for version 1).
  std::map<std::string, OracleMesh> meshes;

  /// The named mesh, or nullptr.
  const OracleMesh* mesh(const std::string& name) const {
    const auto it = meshes.find(name);
    return it == meshes.end() ? nullptr : &it->second;
  }
};

/// Writes an oracle file (version 2) frame by frame (each record is flushed, so a run that dies
/// leaves whole frames behind). Every mesh a frame's draws use must be written with writeMesh
/// before that frame.
class OracleWriter {
 public:
  /// Creates (truncates) `path` and writes the header. Throws std::runtime_error naming the file
  /// if it cannot be opened, std::invalid_argument if a size is zero.
  OracleWriter(const std::string& path, uint32_t width, uint32_t height);

  /// Appends one mesh record. Throws std::invalid_argument if the mesh is inconsistent (see
  /// validateOracleMesh) or its name was written before, std::runtime_error naming the file on a
  /// write error.
  void writeMesh(const OracleMesh& mesh);
  /// Whether writeMesh has written a mesh of this name.
  bool hasMesh(const std::string& name) const { return meshes_.count(name) != 0; }

  /// Appends one frame. Throws std::invalid_argument if the frame is inconsistent (draw indices not
  /// 0..n-1, a name empty or with whitespace, class id > 31, bones on a rigid draw or none on a
  /// skinned one, non-finite numbers, frame number not above the previous one), if a draw's mesh
  /// was not written before, or a skinned draw's mesh has no skin or names a bone the draw lacks;
  /// std::runtime_error naming the file on a write error.
  void write(const OracleFrame& frame);

 private:
  struct WrittenMesh {
    bool skinned = false;
    uint32_t bone_limit = 0;  // highest bone id + 1
  };
  std::string path_;
  std::ofstream out_;
  std::map<std::string, WrittenMesh> meshes_;
  bool has_previous_ = false;
  uint64_t previous_number_ = 0;
};

/// Checks one frame as OracleWriter::write does (without the mesh checks); returns an empty
/// string if it is consistent, else what is wrong.
std::string validateOracleFrame(const OracleFrame& frame);

/// Checks one mesh as OracleWriter::writeMesh does (valid name, 3 coordinates per vertex, all
/// finite, whole triangles with indices below the vertex count, skin of 4 ids and 4 finite weights
/// per vertex or none, bone ids at most 1023); returns an empty string if it is consistent, else
/// what is wrong.
std::string validateOracleMesh(const OracleMesh& mesh);

/// Parses oracle text (version 1 or 2) read from `in`; `source_name` names it in errors. Throws
/// std::runtime_error "<source_name>:<line>: <what is wrong>" on any malformed, inconsistent or
/// truncated input (in version 2 also a draw whose mesh has no record before its frame).
Oracle parseOracle(std::istream& in, const std::string& source_name);

/// Reads an oracle file. Throws std::runtime_error naming the file (and line) if it cannot be
/// opened or is malformed.
Oracle readOracle(const std::string& path);

}  // namespace viper
