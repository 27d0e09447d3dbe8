// A progress bar on stderr for the dataset commands (viper_to_bag, export_viper, generate): one line
// redrawn with '\r' on a terminal, a line per tenth otherwise (logs stay readable). A total of 0 is
// unknown (a capture is read to its end): then the count and the rate, with no bar and no ETA, and
// off a terminal a line at 1-9, 10, 20, ..., 100, 200, ... .
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace viper_tools {

class ProgressBar {
 public:
  ProgressBar(std::string name, size_t total, std::string unit)
      : name_(std::move(name)), unit_(std::move(unit)), total_(total), tty_(isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()) {}

  void update(size_t done) {
    if (total_ == 0) return updateUnknownTotal(done);
    const size_t every = total_ >= 10 ? total_ / 10 : 1;
    if (!tty_ && done % every != 0 && done != total_) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = s > 0 ? done / s : 0.0;
    const double eta = rate > 0 && total_ > done ? (total_ - done) / rate : 0.0;
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? static_cast<int>(kWidth * done / total_) : kWidth;
    std::string bar(filled, '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "%s%s [%s] %zu/%zu %s  %.1f %s/s  ETA %.0f s%s", tty_ ? "\r" : "", name_.c_str(), bar.c_str(),
                 done, total_, unit_.c_str(), rate, unit_.c_str(), eta, tty_ ? "\033[K" : "\n");
    if (tty_ && done == total_) std::fputc('\n', stderr);
    std::fflush(stderr);
    shown_ = true;
  }
  /// Call before printing a message of your own: it must start on a fresh line.
  void interrupt() {
    if (tty_ && shown_) std::fputc('\n', stderr);
    shown_ = false;
  }

 private:
  void updateUnknownTotal(size_t done) {
    size_t every = 1;
    while (every <= done / 10) every *= 10;
    if (!tty_ && done % every != 0) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fprintf(stderr, "%s%s %zu %s (total unknown)  %.1f %s/s%s", tty_ ? "\r" : "", name_.c_str(), done,
                 unit_.c_str(), s > 0 ? done / s : 0.0, unit_.c_str(), tty_ ? "\033[K" : "\n");
    std::fflush(stderr);
    shown_ = true;
  }

  std::string name_, unit_;
  size_t total_;
  bool tty_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace viper_tools
