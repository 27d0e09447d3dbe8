#include "viper/ros/measurement/cpu_meter.h"

#include <time.h>

namespace viper {

CpuMeter::CpuMeter(std::string name, const ros::NodeHandle& nh) : name_(std::move(name)) {
  std::string key;  // the nearest one up the namespaces: a launch file sets it once at its root
  if (nh.searchParam("cpu_report_period_s", key)) nh.getParam(key, period_s_);
  reported_ = ros::WallTime::now();
}

int64_t CpuMeter::threadCpuNs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}

CpuMeter::Scope::Scope(CpuMeter& meter, bool frame) : meter_(meter), frame_(frame), start_ns_(threadCpuNs()) {}

CpuMeter::Scope::~Scope() { meter_.add(threadCpuNs() - start_ns_, frame_); }

void CpuMeter::add(int64_t ns, bool frame) {
  if (period_s_ <= 0.0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  total_ns_ += ns;
  if (frame) ++frames_;
  const ros::WallTime now = ros::WallTime::now();
  if ((now - reported_).toSec() < period_s_ || frames_ == 0) return;
  reported_ = now;
  ROS_INFO("cpu: %s %lu frames, %.2f ms CPU a frame (%.1f ms in all)", name_.c_str(),
           static_cast<unsigned long>(frames_), total_ns_ / 1e6 / static_cast<double>(frames_), total_ns_ / 1e6);
}

}  // namespace viper
