// One process at a time per sequence: two generators given the same sequence (an array resubmitted
// while the first one's task still runs, two shards of a miscounted array) would write the same
// temporary folder and capture. The second waits for the first, then finds the sequence finished.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace viper::dataset {

/// An exclusive flock(2) on a lock file, held while the object lives. The file holds the holder's
/// pid and is removed on release, so a finished dataset has no lock files left; a waiter that finds
/// the file it locked removed (or replaced) opens it again.
class SequenceLock {
public:
  /// Blocks until the lock is held. Before blocking, `waiting` (if set) is called with what the
  /// file says of its holder. Throws std::runtime_error naming the file if it cannot be created.
  explicit SequenceLock(const std::filesystem::path& path,
                        const std::function<void(const std::string& holder)>& waiting = {});
  ~SequenceLock();
  SequenceLock(const SequenceLock&) = delete;
  SequenceLock& operator=(const SequenceLock&) = delete;

  const std::filesystem::path& path() const { return path_; }

private:
  std::filesystem::path path_;
  int fd_ = -1;
};

/// The lock file of sequence `seq` of `split` under a dataset root: a hidden file in the root.
std::filesystem::path sequenceLockPath(const std::filesystem::path& root, const std::string& split,
                                       const std::string& seq);

}  // namespace viper::dataset
