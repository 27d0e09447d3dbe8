#include "viper/dataset/sequence_marker.h"

#include <openssl/evp.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace viper::dataset {

std::string sha256OfFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string() + " for its checksum");
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("OpenSSL cannot start a SHA-256");
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx.get(), buffer.data(), static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) throw std::runtime_error("reading " + path.string() + " failed");
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx.get(), digest, &length);
  std::string hex;
  char byte[3];
  for (unsigned int i = 0; i < length; ++i) {
    std::snprintf(byte, sizeof byte, "%02x", digest[i]);
    hex += byte;
  }
  return hex;
}

void writeSequenceMarker(const std::filesystem::path& path, const SequenceMarker& marker) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << "# frames " << marker.frames << "\n";
    for (const MarkedFile& f : marker.files) out << f.sha256 << "  " << f.relative_path << "\n";
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string() + ": " + ec.message());
}

SequenceMarker readSequenceMarker(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  SequenceMarker m;
  std::string line;
  size_t number = 0;
  bool frames = false;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path.string() + ":" + std::to_string(number);
    if (line.rfind("# frames ", 0) == 0) {
      try {
        m.frames = std::stoull(line.substr(9));
      } catch (const std::exception&) {
        throw std::runtime_error(where + ": bad frame count '" + line + "'");
      }
      frames = true;
      continue;
    }
    if (line.size() < 67 || line.compare(64, 2, "  ") != 0 ||
        line.find_first_not_of("0123456789abcdef") < 64)
      throw std::runtime_error(where + ": not '<sha256>  <path>'");
    m.files.push_back({line.substr(66), line.substr(0, 64)});
  }
  if (!frames) throw std::runtime_error(path.string() + ": no '# frames N' line");
  return m;
}

std::string verifySequence(const std::filesystem::path& root, const SequenceMarker& marker) {
  for (const MarkedFile& f : marker.files) {
    const std::filesystem::path p = root / f.relative_path;
    if (!std::filesystem::is_regular_file(p)) return p.string() + " is missing";
    try {
      if (sha256OfFile(p) != f.sha256) return p.string() + " has another checksum";
    } catch (const std::exception& e) {
      return e.what();
    }
  }
  return "";
}

}  // namespace viper::dataset
