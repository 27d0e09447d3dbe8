// Files written by worker threads while the caller goes on: a dataset frame's PNGs and npz files
// are independent, and encoding them (deflate) costs more than computing the ground truth. Jobs
// run in any order on `threads` workers; submit blocks while `max_pending` jobs wait (back-pressure,
// so memory stays bounded). A job's exception is kept with the file's path and thrown by the next
// check(), drain() or submit(), so a file that cannot be written is never silently lost. Callers
// that want no threads call their job themselves. docs/dataset_generation.md#speed.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace viper::dataset {

class WriteQueue {
 public:
  /// A job writes one file; it may return a note (something about the file that is not an error).
  using Job = std::function<std::string()>;

  /// Throws std::invalid_argument for 0 threads. The threads are named `name` (at most 15
  /// characters: what top -H and perf show).
  WriteQueue(unsigned threads, size_t max_pending, const std::string& name = "viper-writer");
  /// Waits for every job (their errors are dropped here: call drain() first to see them).
  ~WriteQueue();
  WriteQueue(const WriteQueue&) = delete;
  WriteQueue& operator=(const WriteQueue&) = delete;

  /// Queues a job. Throws the first failed job's error.
  void submit(Job job);
  /// Throws std::runtime_error with the first failed job's message, if any; returns the notes of
  /// the jobs done since the last call.
  std::vector<std::string> check();
  /// Waits until every queued job is done, then check().
  std::vector<std::string> drain();

  unsigned threads() const { return static_cast<unsigned>(workers_.size()); }
  /// CPU seconds the workers spent in jobs so far.
  double workerCpuSeconds();

  /// One worker per CPU of this process's affinity mask (what Slurm or taskset grant), at most
  /// `cap`: the caller's own work and the workers' then share the CPUs, whichever is the heavier.
  static unsigned defaultThreads(unsigned cap = 4);

 private:
  void work();

  size_t max_pending_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;
  size_t running_ = 0;
  bool stopping_ = false;
  std::string error_;
  double worker_cpu_s_ = 0;
  std::vector<std::string> notes_;
  std::vector<std::thread> workers_;
};

}  // namespace viper::dataset
