#include "viper/ground_truth/oracle.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <istream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace viper {
namespace {

constexpr const char* kMagic = "viper_oracle";
constexpr int kVersion = 2;  // written; 1 and 2 are read
constexpr uint32_t kMaxClassId = 31;
constexpr uint64_t kMaxBones = 1024;
constexpr uint64_t kMaxMeshElements = uint64_t(1) << 26;  // vertices or triangles of one mesh

bool validName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (std::isspace(static_cast<unsigned char>(c)) || c == '#') return false;
  return true;
}

template <typename Matrix>
void putMatrix(std::ostream& out, const char* tag, const Matrix& m, const char* format) {
  out << tag;
  char buffer[40];
  for (int i = 0; i < 16; ++i) {  // column-major, as glUniformMatrix4fv(transpose = GL_FALSE) reads it
    std::snprintf(buffer, sizeof(buffer), format, static_cast<double>(m.data()[i]));
    out << ' ' << buffer;
  }
  out << '\n';
}

void putFloat(std::ostream& out, float v) {
  char buffer[24];
  std::snprintf(buffer, sizeof(buffer), " %.9g", static_cast<double>(v));
  out << buffer;
}

// Highest bone id of a skinned mesh + 1 (0 for a rigid mesh).
uint32_t boneLimit(const OracleMesh& m) {
  uint32_t limit = 0;
  for (uint32_t id : m.bone_ids) limit = std::max(limit, id + 1);
  return limit;
}

// What is wrong with a draw (skinned or not, with `bone_count` bones) of a mesh, or "". A rigid
// draw of a skinned mesh is allowed: its skin is unused.
std::string drawMeshProblem(const std::string& mesh, bool skinned, size_t bone_count, bool mesh_skinned,
                            uint32_t bone_limit) {
  if (skinned && !mesh_skinned) return "skinned draw of mesh " + mesh + ", which has no bone weights";
  if (skinned && bone_limit > bone_count)
    return "mesh " + mesh + " uses bone " + std::to_string(bone_limit - 1) + " but the draw has " +
           std::to_string(bone_count) + " bones";
  return "";
}

// Reads the file line by line, skipping blank and comment lines, and reports errors with the line.
class LineReader {
 public:
  LineReader(std::istream& in, const std::string& source) : in_(in), source_(source) {}

  // Next non-empty line split into tokens; false at the end of the input.
  bool next(std::vector<std::string>& tokens) {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_;
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream split(line);
      tokens.clear();
      for (std::string t; split >> t;) tokens.push_back(t);
      if (!tokens.empty()) return true;
    }
    if (in_.bad()) fail("read error");
    return false;
  }

  // Next line, which must start with `tag` and have `count` values after it.
  std::vector<std::string> expect(const std::string& tag, size_t count) {
    std::vector<std::string> tokens;
    if (!next(tokens)) fail("unexpected end of file, expected '" + tag + "' (truncated file?)");
    if (tokens[0] != tag) fail("expected '" + tag + "', got '" + tokens[0] + "'");
    if (tokens.size() != count + 1)
      fail("'" + tag + "' needs " + std::to_string(count) + " values, got " + std::to_string(tokens.size() - 1));
    return tokens;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(source_ + ":" + std::to_string(line_) + ": " + what);
  }

  double real(const std::string& token) const {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
      fail("'" + token + "' is not a finite number");
    return v;
  }

  uint64_t integer(const std::string& token, uint64_t max) const {
    errno = 0;
    char* end = nullptr;
    if (token.empty() || token[0] == '-' || token[0] == '+') fail("'" + token + "' is not a non-negative integer");
    const unsigned long long v = std::strtoull(token.c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE) fail("'" + token + "' is not a non-negative integer");
    if (v > max) fail("'" + token + "' is out of range (max " + std::to_string(max) + ")");
    return v;
  }

  template <typename Matrix>
  Matrix matrix(const std::string& tag) {
    const std::vector<std::string> t = expect(tag, 16);
    Matrix m;
    for (int i = 0; i < 16; ++i) {
      const double v = real(t[i + 1]);
      using Scalar = typename Matrix::Scalar;
      if (std::fabs(v) > static_cast<double>(std::numeric_limits<Scalar>::max()))
        fail("'" + t[i + 1] + "' does not fit the matrix's number type");
      m.data()[i] = static_cast<Scalar>(v);
    }
    return m;
  }

 private:
  std::istream& in_;
  const std::string& source_;
  size_t line_ = 0;
};

// A mesh record whose first line is `t`: the vertex and triangle lines that follow.
OracleMesh parseMesh(LineReader& r, const std::vector<std::string>& t) {
  if (t.size() != 5) r.fail("'mesh' needs 4 values (name, vertex count, triangle count, skinned)");
  OracleMesh m;
  m.name = t[1];
  if (!validName(m.name)) r.fail("mesh name '" + m.name + "' is not a valid name");
  const uint64_t vertices = r.integer(t[2], kMaxMeshElements);
  const uint64_t triangles = r.integer(t[3], kMaxMeshElements);
  const bool skinned = r.integer(t[4], 1) == 1;
  std::vector<std::string> v;
  for (uint64_t i = 0; i < vertices; ++i) {
    v = r.expect("v", skinned ? 11 : 3);
    for (int k = 1; k <= 3; ++k) {
      const double x = r.real(v[k]);
      if (std::fabs(x) > std::numeric_limits<float>::max()) r.fail("'" + v[k] + "' does not fit a float");
      m.positions_xyz.push_back(static_cast<float>(x));
    }
    if (!skinned) continue;
    for (int k = 4; k <= 7; ++k) m.bone_ids.push_back(static_cast<uint32_t>(r.integer(v[k], kMaxBones - 1)));
    for (int k = 8; k <= 11; ++k) {
      const double w = r.real(v[k]);
      if (std::fabs(w) > std::numeric_limits<float>::max()) r.fail("'" + v[k] + "' does not fit a float");
      m.bone_weights.push_back(static_cast<float>(w));
    }
  }
  for (uint64_t i = 0; i < triangles; ++i) {
    v = r.expect("t", 3);
    for (int k = 1; k <= 3; ++k) {
      if (vertices == 0) r.fail("mesh " + m.name + " has triangles but no vertices");
      m.indices.push_back(static_cast<uint32_t>(r.integer(v[k], vertices - 1)));
    }
  }
  return m;
}

}  // namespace

std::string validateOracleFrame(const OracleFrame& frame) {
  if (!std::isfinite(frame.time_s)) return "frame time is not finite";
  if (!frame.view.allFinite() || !frame.projection.allFinite() || !frame.map_from_camera_body.allFinite())
    return "camera matrices are not finite";
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    const OracleDraw& d = frame.draws[i];
    const std::string where = "draw " + std::to_string(i) + ": ";
    if (d.index != i) return where + "index is " + std::to_string(d.index) + ", expected " + std::to_string(i);
    if (d.class_id > kMaxClassId) return where + "class id " + std::to_string(d.class_id) + " is above 31";
    if (!validName(d.part)) return where + "part name '" + d.part + "' is empty or has whitespace or '#'";
    if (!validName(d.mesh)) return where + "mesh name '" + d.mesh + "' is empty or has whitespace or '#'";
    if (!d.world.allFinite()) return where + "world matrix is not finite";
    if (d.skinned && d.bones.empty()) return where + "skinned but has no bones";
    if (!d.skinned && !d.bones.empty()) return where + "rigid but has bones";
    for (const GlMatrix& b : d.bones)
      if (!b.allFinite()) return where + "a bone matrix is not finite";
  }
  return "";
}

std::string validateOracleMesh(const OracleMesh& m) {
  if (!validName(m.name)) return "mesh name '" + m.name + "' is empty or has whitespace or '#'";
  const std::string where = "mesh " + m.name + ": ";
  if (m.positions_xyz.size() % 3 != 0) return where + "positions are not 3 per vertex";
  if (m.indices.size() % 3 != 0) return where + "indices are not 3 per triangle";
  if (m.vertexCount() > kMaxMeshElements || m.triangleCount() > kMaxMeshElements) return where + "too large";
  for (float v : m.positions_xyz)
    if (!std::isfinite(v)) return where + "a position is not finite";
  const size_t n = m.vertexCount();
  for (uint32_t i : m.indices)
    if (i >= n) return where + "index " + std::to_string(i) + " is not below the vertex count " + std::to_string(n);
  if (m.bone_ids.size() != m.bone_weights.size() || (!m.bone_ids.empty() && m.bone_ids.size() != 4 * n))
    return where + "bone ids and weights must both be 4 per vertex, or both empty";
  for (uint32_t id : m.bone_ids)
    if (id >= kMaxBones) return where + "bone id " + std::to_string(id) + " is above 1023";
  for (float w : m.bone_weights)
    if (!std::isfinite(w)) return where + "a bone weight is not finite";
  return "";
}

OracleWriter::OracleWriter(const std::string& path, uint32_t width, uint32_t height)
    : path_(path), out_(path, std::ios::out | std::ios::trunc) {
  if (width == 0 || height == 0) throw std::invalid_argument("oracle " + path + ": image size must not be zero");
  if (!out_) throw std::runtime_error("oracle " + path + ": cannot open for writing");
  out_ << kMagic << ' ' << kVersion << '\n' << "size " << width << ' ' << height << '\n';
  out_.flush();
  if (!out_) throw std::runtime_error("oracle " + path + ": write error");
}

void OracleWriter::writeMesh(const OracleMesh& m) {
  const std::string problem = validateOracleMesh(m);
  if (!problem.empty()) throw std::invalid_argument("oracle " + path_ + ": " + problem);
  if (hasMesh(m.name)) throw std::invalid_argument("oracle " + path_ + ": mesh " + m.name + " written twice");
  const size_t n = m.vertexCount();
  out_ << "mesh " << m.name << ' ' << n << ' ' << m.triangleCount() << ' ' << (m.skinned() ? 1 : 0) << '\n';
  for (size_t v = 0; v < n; ++v) {
    out_ << 'v';
    for (int k = 0; k < 3; ++k) putFloat(out_, m.positions_xyz[3 * v + k]);
    if (m.skinned()) {
      for (int k = 0; k < 4; ++k) out_ << ' ' << m.bone_ids[4 * v + k];
      for (int k = 0; k < 4; ++k) putFloat(out_, m.bone_weights[4 * v + k]);
    }
    out_ << '\n';
  }
  for (size_t t = 0; t < m.triangleCount(); ++t)
    out_ << "t " << m.indices[3 * t] << ' ' << m.indices[3 * t + 1] << ' ' << m.indices[3 * t + 2] << '\n';
  out_.flush();
  if (!out_) throw std::runtime_error("oracle " + path_ + ": write error");
  meshes_[m.name] = WrittenMesh{m.skinned(), boneLimit(m)};
}

void OracleWriter::write(const OracleFrame& frame) {
  std::string problem = validateOracleFrame(frame);
  for (size_t i = 0; i < frame.draws.size() && problem.empty(); ++i) {
    const OracleDraw& d = frame.draws[i];
    const auto it = meshes_.find(d.mesh);
    problem = it == meshes_.end() ? "mesh " + d.mesh + " was not written before"
                                  : drawMeshProblem(d.mesh, d.skinned, d.bones.size(), it->second.skinned,
                                                    it->second.bone_limit);
    if (!problem.empty()) problem = "draw " + std::to_string(i) + ": " + problem;
  }
  if (!problem.empty())
    throw std::invalid_argument("oracle " + path_ + ": frame " + std::to_string(frame.number) + ": " + problem);
  if (has_previous_ && frame.number <= previous_number_)
    throw std::invalid_argument("oracle " + path_ + ": frame number " + std::to_string(frame.number) +
                                " does not follow " + std::to_string(previous_number_));
  char time[40];
  std::snprintf(time, sizeof(time), "%.17g", frame.time_s);
  out_ << "frame " << frame.number << ' ' << time << ' ' << frame.draws.size() << '\n';
  putMatrix(out_, "view", frame.view, "%.9g");
  putMatrix(out_, "projection", frame.projection, "%.9g");
  putMatrix(out_, "camera_pose", frame.map_from_camera_body, "%.17g");
  for (const OracleDraw& d : frame.draws) {
    out_ << "draw " << d.index << ' ' << d.object_id << ' ' << d.class_id << ' ' << d.part << ' ' << d.mesh << ' '
         << (d.skinned ? 1 : 0) << ' ' << d.bones.size() << '\n';
    putMatrix(out_, "world", d.world, "%.9g");
    for (const GlMatrix& b : d.bones) putMatrix(out_, "bone", b, "%.9g");
  }
  out_.flush();
  if (!out_) throw std::runtime_error("oracle " + path_ + ": write error");
  has_previous_ = true;
  previous_number_ = frame.number;
}

Oracle parseOracle(std::istream& in, const std::string& source_name) {
  LineReader r(in, source_name);
  Oracle oracle;
  std::vector<std::string> t;
  if (!r.next(t)) r.fail("empty file, expected '" + std::string(kMagic) + " " + std::to_string(kVersion) + "'");
  if (t.size() != 2 || t[0] != kMagic) r.fail("not an oracle file (expected '" + std::string(kMagic) + " 2')");
  oracle.version = static_cast<int>(r.integer(t[1], 1000));
  if (oracle.version != 1 && oracle.version != 2) r.fail("unsupported oracle version " + t[1] + " (1 and 2 are read)");
  t = r.expect("size", 2);
  oracle.width = static_cast<uint32_t>(r.integer(t[1], UINT32_MAX));
  oracle.height = static_cast<uint32_t>(r.integer(t[2], UINT32_MAX));
  if (oracle.width == 0 || oracle.height == 0) r.fail("image size must not be zero");

  std::map<std::string, uint32_t> bone_limits;
  while (r.next(t)) {
    if (t[0] == "mesh" && oracle.version >= 2) {
      if (t.size() > 1 && oracle.meshes.count(t[1])) r.fail("mesh " + t[1] + " appears twice");
      OracleMesh m = parseMesh(r, t);
      bone_limits[m.name] = boneLimit(m);
      oracle.meshes.emplace(m.name, std::move(m));
      continue;
    }
    if (t[0] != "frame")
      r.fail("expected '" + std::string(oracle.version >= 2 ? "frame' or 'mesh" : "frame") + "', got '" + t[0] + "'");
    if (t.size() != 4) r.fail("'frame' needs 3 values (number, time, draw count)");
    OracleFrame f;
    f.number = r.integer(t[1], UINT64_MAX);
    f.time_s = r.real(t[2]);
    const uint64_t draw_count = r.integer(t[3], 1u << 24);
    if (!oracle.frames.empty() && f.number <= oracle.frames.back().number)
      r.fail("frame number " + t[1] + " does not follow " + std::to_string(oracle.frames.back().number));
    f.view = r.matrix<GlMatrix>("view");
    f.projection = r.matrix<GlMatrix>("projection");
    f.map_from_camera_body = r.matrix<Eigen::Matrix4d>("camera_pose");
    for (uint64_t i = 0; i < draw_count; ++i) {
      t = r.expect("draw", 7);
      OracleDraw d;
      d.index = static_cast<uint32_t>(r.integer(t[1], UINT32_MAX));
      if (d.index != i) r.fail("draw index " + t[1] + ", expected " + std::to_string(i));
      d.object_id = static_cast<uint32_t>(r.integer(t[2], UINT32_MAX));
      d.class_id = static_cast<uint32_t>(r.integer(t[3], kMaxClassId));
      d.part = t[4];
      d.mesh = t[5];
      d.skinned = r.integer(t[6], 1) == 1;
      const uint64_t bone_count = r.integer(t[7], 1024);
      if (d.skinned != (bone_count > 0)) r.fail(d.skinned ? "skinned draw without bones" : "rigid draw with bones");
      if (oracle.version >= 2) {
        const OracleMesh* mesh = oracle.mesh(d.mesh);
        if (!mesh) r.fail("draw " + t[1] + ": mesh " + d.mesh + " has no mesh record before this frame");
        const std::string problem =
            drawMeshProblem(d.mesh, d.skinned, bone_count, mesh->skinned(), bone_limits[d.mesh]);
        if (!problem.empty()) r.fail("draw " + t[1] + ": " + problem);
      }
      d.world = r.matrix<GlMatrix>("world");
      for (uint64_t b = 0; b < bone_count; ++b) d.bones.push_back(r.matrix<GlMatrix>("bone"));
      f.draws.push_back(std::move(d));
    }
    oracle.frames.push_back(std::move(f));
  }
  return oracle;
}

Oracle readOracle(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("oracle " + path + ": cannot open file");
  return parseOracle(in, path);
}

}  // namespace viper
