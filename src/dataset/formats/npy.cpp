#include "viper/dataset/npy.h"

#include <cctype>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace viper::dataset {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;
// Our readers take images; a header this long is damage, not data.
constexpr size_t kMaxHeaderSize = 1 << 20;

[[noreturn]] void fail(const std::string& name, size_t offset, const std::string& what) {
  throw std::runtime_error(name + ": " + what + " (npy byte offset " + std::to_string(offset) + ")");
}

// A parser for the one Python dict literal numpy writes: string keys; string, boolean and
// integer-tuple values.
class HeaderParser {
 public:
  HeaderParser(const std::string& text, size_t base, const std::string& name)
      : s_(text), base_(base), name_(name) {}

  NpyHeader parse() {
    NpyHeader a;
    bool have_descr = false, have_order = false, have_shape = false;
    expect('{');
    while (true) {
      skipSpace();
      if (peek() == '}') break;
      const size_t key_at = at();
      const std::string key = parseString();
      expect(':');
      if (key == "descr") {
        skipSpace();
        if (peek() != '\'' && peek() != '"') fail(name_, at(), "'descr' is not a simple type string");
        a.descr = parseString();
        have_descr = true;
      } else if (key == "fortran_order") {
        a.fortran_order = parseBool();
        have_order = true;
      } else if (key == "shape") {
        a.shape = parseShape();
        have_shape = true;
      } else {
        fail(name_, key_at, "unexpected header key '" + key + "'");
      }
      skipSpace();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      skipSpace();
      if (peek() != '}') fail(name_, at(), "expected ',' or '}' in header");
    }
    ++i_;
    if (!have_descr || !have_order || !have_shape)
      fail(name_, at(), "header lacks 'descr', 'fortran_order' or 'shape'");
    skipSpace();
    if (i_ != s_.size()) fail(name_, at(), "trailing characters after the header dict");
    return a;
  }

 private:
  size_t at() const { return base_ + i_; }
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void skipSpace() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  void expect(char c) {
    skipSpace();
    if (peek() != c) fail(name_, at(), std::string("expected '") + c + "' in header");
    ++i_;
  }
  std::string parseString() {
    skipSpace();
    const char q = peek();
    if (q != '\'' && q != '"') fail(name_, at(), "expected a quoted string in header");
    const size_t end = s_.find(q, i_ + 1);
    if (end == std::string::npos) fail(name_, at(), "unterminated string in header");
    std::string out = s_.substr(i_ + 1, end - i_ - 1);
    i_ = end + 1;
    return out;
  }
  bool parseBool() {
    skipSpace();
    if (s_.compare(i_, 4, "True") == 0) {
      i_ += 4;
      return true;
    }
    if (s_.compare(i_, 5, "False") == 0) {
      i_ += 5;
      return false;
    }
    fail(name_, at(), "'fortran_order' is neither True nor False");
  }
  std::vector<uint64_t> parseShape() {
    std::vector<uint64_t> shape;
    expect('(');
    while (true) {
      skipSpace();
      if (peek() == ')') break;
      if (!std::isdigit(static_cast<unsigned char>(peek()))) fail(name_, at(), "bad 'shape' in header");
      uint64_t v = 0;
      while (std::isdigit(static_cast<unsigned char>(peek()))) {
        const uint64_t d = static_cast<uint64_t>(s_[i_++] - '0');
        if (v > (std::numeric_limits<uint64_t>::max() - d) / 10) fail(name_, at(), "'shape' overflows");
        v = v * 10 + d;
      }
      if (peek() == 'L') ++i_;  // Python 2 wrote long integers as 1080L
      shape.push_back(v);
      skipSpace();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      if (peek() != ')') fail(name_, at(), "expected ',' or ')' in 'shape'");
    }
    ++i_;
    return shape;
  }

  const std::string& s_;
  size_t base_;
  const std::string& name_;
  size_t i_ = 0;
};

std::string shapeText(const std::vector<uint64_t>& shape) {
  std::string s = "(";
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

}  // namespace

size_t npyItemSize(const std::string& descr) {
  if (descr.size() < 3 || std::strchr("<>|=", descr[0]) == nullptr ||
      !std::isalpha(static_cast<unsigned char>(descr[1])))
    throw std::invalid_argument("unsupported npy type '" + descr + "'");
  size_t size = 0;
  for (size_t i = 2; i < descr.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(descr[i])) || size > 1000)
      throw std::invalid_argument("unsupported npy type '" + descr + "'");
    size = size * 10 + static_cast<size_t>(descr[i] - '0');
  }
  if (size == 0) throw std::invalid_argument("unsupported npy type '" + descr + "'");
  return size;
}

uint64_t npyElementCount(const std::vector<uint64_t>& shape) {
  uint64_t n = 1;
  for (uint64_t d : shape) {
    if (d != 0 && n > std::numeric_limits<uint64_t>::max() / d)
      throw std::invalid_argument("npy shape " + shapeText(shape) + " overflows");
    n *= d;
  }
  return n;
}

std::vector<uint8_t> encodeNpyHeader(const std::string& descr, bool fortran_order,
                                     const std::vector<uint64_t>& shape) {
  npyItemSize(descr);
  std::string header = "{'descr': '" + descr + "', 'fortran_order': " + (fortran_order ? "True" : "False") +
                       ", 'shape': " + shapeText(shape) + ", }";
  // numpy pads with spaces so that magic + version + length + header + '\n' is a multiple of 64.
  const size_t prefix = kMagicSize + 2 + 2;
  const size_t total = (prefix + header.size() + 1 + 63) / 64 * 64;
  header.append(total - prefix - header.size() - 1, ' ');
  header += '\n';
  if (header.size() > 0xffff) throw std::invalid_argument("npy header too long for version 1.0");
  // Filled with memcpy: GCC 12 at -O3 warns falsely about vector::insert of a few bytes.
  std::vector<uint8_t> out(total);
  std::memcpy(out.data(), kMagic, kMagicSize);
  out[kMagicSize] = 1;
  out[kMagicSize + 1] = 0;
  out[kMagicSize + 2] = static_cast<uint8_t>(header.size() & 0xff);
  out[kMagicSize + 3] = static_cast<uint8_t>(header.size() >> 8);
  std::memcpy(out.data() + prefix, header.data(), header.size());
  return out;
}

std::vector<uint8_t> encodeNpy(const NpyArray& array) {
  const uint64_t count = npyElementCount(array.shape);
  const size_t item = npyItemSize(array.descr);
  if (count > std::numeric_limits<uint64_t>::max() / item || count * item != array.data.size())
    throw std::invalid_argument("npy data of " + std::to_string(array.data.size()) +
                                " bytes does not match shape " + shapeText(array.shape) + " of '" +
                                array.descr + "'");
  std::vector<uint8_t> out = encodeNpyHeader(array.descr, array.fortran_order, array.shape);
  const size_t head = out.size();
  out.resize(head + array.data.size());
  if (!array.data.empty()) std::memcpy(out.data() + head, array.data.data(), array.data.size());
  return out;
}

NpyHeader decodeNpyHeader(const uint8_t* bytes, size_t size, const std::string& name) {
  if (size < kMagicSize + 2 || std::memcmp(bytes, kMagic, kMagicSize) != 0)
    fail(name, 0, "not an npy array (no \\x93NUMPY magic)");
  const uint8_t major = bytes[kMagicSize], minor = bytes[kMagicSize + 1];
  if (major < 1 || major > 3 || minor != 0)
    fail(name, kMagicSize, "unsupported npy version " + std::to_string(major) + "." + std::to_string(minor));
  const size_t len_size = major == 1 ? 2 : 4;
  size_t pos = kMagicSize + 2;
  if (size < pos + len_size) fail(name, pos, "truncated npy header length");
  size_t header_size = 0;
  for (size_t i = 0; i < len_size; ++i) header_size |= static_cast<size_t>(bytes[pos + i]) << (8 * i);
  pos += len_size;
  if (header_size > kMaxHeaderSize) fail(name, pos, "npy header length " + std::to_string(header_size) + " is absurd");
  if (size - pos < header_size)
    fail(name, pos, "truncated npy header: " + std::to_string(header_size) + " bytes announced, " +
                        std::to_string(size - pos) + " present");
  const std::string header(reinterpret_cast<const char*>(bytes + pos), header_size);
  NpyHeader a = HeaderParser(header, pos, name).parse();
  pos += header_size;
  a.data_offset = pos;

  size_t item = 0;
  uint64_t count = 0;
  try {
    item = npyItemSize(a.descr);
    count = npyElementCount(a.shape);
  } catch (const std::invalid_argument& e) {
    fail(name, kMagicSize + 2 + len_size, e.what());
  }
  const size_t present = size - pos;
  if (count > present / item || count * item != present)
    fail(name, pos, "npy data is " + std::to_string(present) + " bytes, but shape " + shapeText(a.shape) +
                        " of '" + a.descr + "' needs " +
                        (count > std::numeric_limits<uint64_t>::max() / item ? std::string("more")
                                                                             : std::to_string(count * item)));
  return a;
}

NpyArray decodeNpy(const uint8_t* bytes, size_t size, const std::string& name) {
  NpyHeader h = decodeNpyHeader(bytes, size, name);
  NpyArray a;
  a.descr = std::move(h.descr);
  a.fortran_order = h.fortran_order;
  a.shape = std::move(h.shape);
  a.data.assign(bytes + h.data_offset, bytes + size);
  return a;
}

}  // namespace viper::dataset
