#include "viper/dataset/write_queue.h"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <stdexcept>

namespace viper::dataset {
namespace {
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
}  // namespace

WriteQueue::WriteQueue(unsigned threads, size_t max_pending, const std::string& name)
    : max_pending_(std::max<size_t>(1, max_pending)) {
  if (threads == 0) throw std::invalid_argument("a write queue needs at least one thread");
  for (unsigned i = 0; i < threads; ++i) {
    workers_.emplace_back(&WriteQueue::work, this);
    pthread_setname_np(workers_.back().native_handle(), name.substr(0, 15).c_str());
  }
}

WriteQueue::~WriteQueue() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return jobs_.empty() && running_ == 0; });
    stopping_ = true;
  }
  changed_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void WriteQueue::submit(Job job) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return jobs_.size() < max_pending_ || !error_.empty(); });
  if (!error_.empty()) throw std::runtime_error(error_);
  jobs_.push_back(std::move(job));
  lock.unlock();
  changed_.notify_all();
}

std::vector<std::string> WriteQueue::check() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!error_.empty()) throw std::runtime_error(error_);
  std::vector<std::string> notes;
  notes.swap(notes_);
  return notes;
}

std::vector<std::string> WriteQueue::drain() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return jobs_.empty() && running_ == 0; });
  }
  return check();
}

void WriteQueue::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
    if (jobs_.empty()) return;  // stopping, nothing left
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    ++running_;
    lock.unlock();
    changed_.notify_all();  // a submit waiting for room
    std::string note, error;
    const double cpu0 = threadCpuSeconds();
    try {
      note = job();
    } catch (const std::exception& e) {
      error = e.what();
    }
    const double cpu = threadCpuSeconds() - cpu0;
    lock.lock();
    worker_cpu_s_ += cpu;
    --running_;
    if (!error.empty() && error_.empty()) error_ = error;
    if (!note.empty()) notes_.push_back(std::move(note));
    changed_.notify_all();
  }
}

double WriteQueue::workerCpuSeconds() {
  std::lock_guard<std::mutex> lock(mutex_);
  return worker_cpu_s_;
}

unsigned WriteQueue::defaultThreads(unsigned cap) {
  cpu_set_t set;
  CPU_ZERO(&set);
  int cpus = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 1;
  return static_cast<unsigned>(std::clamp(cpus, 1, static_cast<int>(cap)));
}

}  // namespace viper::dataset
