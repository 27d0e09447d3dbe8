// Where a sequence's time goes: CPU time of this thread and wall time per named stage (reading,
// each ground-truth step, each writer), accumulated over the frames and printed by `generate` as
// milliseconds a frame. CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID), so that other
// processes on the machine do not inflate it; wall time beside it shows waiting (disk, page cache).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace viper {

class StageTimes {
 public:
  struct Stage {
    std::string name;
    double cpu_s = 0, wall_s = 0;
  };

  /// Adds to `name` (a new stage goes last, so the table keeps the order of the first calls).
  void add(const std::string& name, double cpu_s, double wall_s);
  const std::vector<Stage>& stages() const { return stages_; }
  double totalCpu() const;
  double totalWall() const;
  /// A table for `frames` frames: stage, CPU ms a frame, wall ms a frame, share of the CPU.
  std::string table(uint64_t frames) const;

 private:
  std::vector<Stage> stages_;
};

/// Adds the CPU and wall time from its construction to its destruction to a stage; does nothing
/// without StageTimes.
class StageTimer {
 public:
  StageTimer(StageTimes* times, const char* name);
  ~StageTimer();
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  StageTimes* times_;
  const char* name_;
  double cpu0_ = 0, wall0_ = 0;
};

}  // namespace viper
