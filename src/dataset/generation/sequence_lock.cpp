#include "viper/dataset/sequence_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace viper::dataset {

namespace {

std::string readHolder(int fd) {
  char text[64] = {};
  const ssize_t n = ::pread(fd, text, sizeof(text) - 1, 0);
  return n > 0 ? std::string(text, static_cast<size_t>(n)) : std::string("an unknown process");
}

// The open file is still the one at `path` (not removed or replaced by its last holder).
bool stillThere(int fd, const std::filesystem::path& path) {
  struct stat open_file {}, named {};
  return ::fstat(fd, &open_file) == 0 && ::stat(path.c_str(), &named) == 0 && open_file.st_dev == named.st_dev &&
         open_file.st_ino == named.st_ino;
}

}  // namespace

SequenceLock::SequenceLock(const std::filesystem::path& path,
                           const std::function<void(const std::string& holder)>& waiting)
    : path_(path) {
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  bool told = false;
  for (;;) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error(path.string() + ": cannot create the lock file: " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (errno != EWOULDBLOCK) {
        const int e = errno;
        ::close(fd_);
        throw std::runtime_error(path.string() + ": cannot lock: " + std::strerror(e));
      }
      if (waiting && !told) waiting(readHolder(fd_));
      told = true;
      while (::flock(fd_, LOCK_EX) != 0) {
        if (errno == EINTR) continue;
        const int e = errno;
        ::close(fd_);
        throw std::runtime_error(path.string() + ": cannot lock: " + std::strerror(e));
      }
    }
    if (stillThere(fd_, path)) break;
    ::close(fd_);  // the holder removed it on release: lock the file that is there now
  }
  const std::string me = "pid " + std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size())) {
    // The pid is only for the message of a waiter: the lock itself holds.
  }
}

SequenceLock::~SequenceLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // while still held: a waiter then sees its file gone and opens anew
  ::close(fd_);
}

std::filesystem::path sequenceLockPath(const std::filesystem::path& root, const std::string& split,
                                       const std::string& seq) {
  return root / ("." + split + "_" + seq + ".lock");
}

}  // namespace viper::dataset
