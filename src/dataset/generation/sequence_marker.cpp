#include "viper/dataset/sequence_marker.h"

#include "viper/dataset/file_digests.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>

namespace viper::dataset {

namespace {

// Reads `path` front to back into `digest`. A big file (the bag, written around the page cache)
// is read around the cache too (O_DIRECT) where the file system allows: it is not read again soon,
// and pulling it into the cache costs more kernel CPU than the hash on a VM whose memory is full of
// cache (direct_file.h). The next piece is read while one is hashed (the disk and the CPU at work
// at once: a shard's marker stage otherwise waits on the disk as long as it hashes).
void digestFile(const std::filesystem::path& path, Sha256& digest) {
  constexpr size_t kAlign = 4096, kBuffer = 8u << 20;
  // Small files (the layout's, a few MB, written through the cache moments ago) are read from the
  // cache: reading them directly would first wait for their dirty pages to reach the disk.
  std::error_code size_error;
  const bool big = std::filesystem::file_size(path, size_error) >= kBuffer && !size_error;
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (big ? O_DIRECT : 0));
  if (fd < 0 && errno == EINVAL) fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot read " + path.string() + " for its checksum: " + std::strerror(errno));
  const std::unique_ptr<int, void (*)(int*)> closer(&fd, [](int* f) { ::close(*f); });
  std::unique_ptr<void, void (*)(void*)> buffers[2] = {{nullptr, std::free}, {nullptr, std::free}};
  for (auto& b : buffers) {
    void* p = nullptr;
    if (posix_memalign(&p, kAlign, kBuffer) != 0) throw std::bad_alloc();
    b.reset(p);
  }
  auto readPiece = [&](void* into) -> ssize_t {  // -errno on failure
    for (;;) {
      const ssize_t n = ::read(fd, into, kBuffer);
      if (n >= 0) return n;
      if (errno != EINTR) return -errno;
    }
  };
  ssize_t n = readPiece(buffers[0].get());
  for (size_t current = 0; n > 0; current ^= 1) {
    std::future<ssize_t> next = std::async(std::launch::async, readPiece, buffers[current ^ 1].get());
    digest.update(buffers[current].get(), static_cast<size_t>(n));
    n = next.get();
  }
  if (n < 0) throw std::runtime_error("reading " + path.string() + " failed: " + std::strerror(static_cast<int>(-n)));
}

}  // namespace

std::string sha256OfFile(const std::filesystem::path& path) {
  Sha256 digest;
  digestFile(path, digest);
  return digest.hex();
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
