// CPU time a node spends on its frames, for scripts/measure_pipeline.sh's per-nodelet table: the
// thread CPU time of its callbacks (nodelets share the manager's threads, so the process's time says
// nothing per nodelet), logged every cpu_report_period_s seconds (the parameter nearest up the node's
// namespaces, e.g. /cpu_report_period_s from replay.launch's cpu_report_period; 0, the default:
// never) as
// "cpu: NAME N frames, X ms CPU a frame (Y ms in all)". Used by every ground-truth nodelet and the
// players (bag_player, capture_bridge).
#pragma once

#include <ros/ros.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

namespace viper {

class CpuMeter {
 public:
  /// `name` goes into the report; the period is the parameter cpu_report_period_s searched from
  /// `nh`'s namespace up.
  CpuMeter(std::string name, const ros::NodeHandle& nh);

  /// Adds this thread's CPU time from construction to destruction; `frame`: counts one frame.
  class Scope {
   public:
    Scope(CpuMeter& meter, bool frame);
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    CpuMeter& meter_;
    bool frame_;
    int64_t start_ns_;
  };

  /// This thread's CPU time so far, nanoseconds.
  static int64_t threadCpuNs();
  /// Adds `ns` of CPU time; `frame`: counts one frame (a player's thread measures itself with it).
  void add(int64_t ns, bool frame);

 private:
  std::string name_;
  double period_s_ = 0.0;
  std::mutex mutex_;
  int64_t total_ns_ = 0;
  uint64_t frames_ = 0;
  ros::WallTime reported_;
};

}  // namespace viper
