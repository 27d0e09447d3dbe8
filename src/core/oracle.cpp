#include "viper/core/oracle.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <istream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace viper {
namespace {

constexpr const char* kMagic = "viper_oracle";
constexpr int kVersion = 1;
constexpr uint32_t kMaxClassId = 31;

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

OracleWriter::OracleWriter(const std::string& path, uint32_t width, uint32_t height)
    : path_(path), out_(path, std::ios::out | std::ios::trunc) {
  if (width == 0 || height == 0) throw std::invalid_argument("oracle " + path + ": image size must not be zero");
  if (!out_) throw std::runtime_error("oracle " + path + ": cannot open for writing");
  out_ << kMagic << ' ' << kVersion << '\n' << "size " << width << ' ' << height << '\n';
  out_.flush();
  if (!out_) throw std::runtime_error("oracle " + path + ": write error");
}

void OracleWriter::write(const OracleFrame& frame) {
  const std::string problem = validateOracleFrame(frame);
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
  if (t.size() != 2 || t[0] != kMagic) r.fail("not an oracle file (expected '" + std::string(kMagic) + " 1')");
  if (r.integer(t[1], 1000) != kVersion) r.fail("unsupported oracle version " + t[1]);
  t = r.expect("size", 2);
  oracle.width = static_cast<uint32_t>(r.integer(t[1], UINT32_MAX));
  oracle.height = static_cast<uint32_t>(r.integer(t[2], UINT32_MAX));
  if (oracle.width == 0 || oracle.height == 0) r.fail("image size must not be zero");

  while (r.next(t)) {
    if (t[0] != "frame") r.fail("expected 'frame', got '" + t[0] + "'");
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
