#include "viper/ground_truth/stage_times.h"

#include <ctime>
#include <iomanip>
#include <sstream>

namespace viper {
namespace {
double seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
}  // namespace

void StageTimes::add(const std::string& name, double cpu_s, double wall_s) {
  for (Stage& s : stages_)
    if (s.name == name) {
      s.cpu_s += cpu_s;
      s.wall_s += wall_s;
      return;
    }
  stages_.push_back({name, cpu_s, wall_s});
}

double StageTimes::totalCpu() const {
  double t = 0;
  for (const Stage& s : stages_) t += s.cpu_s;
  return t;
}

double StageTimes::totalWall() const {
  double t = 0;
  for (const Stage& s : stages_) t += s.wall_s;
  return t;
}

std::string StageTimes::table(uint64_t frames) const {
  std::ostringstream out;
  const double n = frames ? double(frames) : 1.0, cpu = totalCpu();
  out << std::fixed << std::setprecision(1) << std::left << std::setw(16) << "stage" << std::right
      << std::setw(10) << "CPU ms" << std::setw(10) << "wall ms" << std::setw(8) << "CPU %"
      << "   (a frame, over " << frames << " frames)\n";
  for (const Stage& s : stages_)
    out << std::left << std::setw(16) << s.name << std::right << std::setw(10) << 1e3 * s.cpu_s / n
        << std::setw(10) << 1e3 * s.wall_s / n << std::setw(8) << (cpu > 0 ? 100.0 * s.cpu_s / cpu : 0.0) << "\n";
  out << std::left << std::setw(16) << "total" << std::right << std::setw(10) << 1e3 * cpu / n << std::setw(10)
      << 1e3 * totalWall() / n << std::setw(8) << 100.0 << "\n";
  return out.str();
}

StageTimer::StageTimer(StageTimes* times, const char* name) : times_(times), name_(name) {
  if (!times_) return;
  cpu0_ = seconds(CLOCK_THREAD_CPUTIME_ID);
  wall0_ = seconds(CLOCK_MONOTONIC);
}

StageTimer::~StageTimer() {
  if (!times_) return;
  times_->add(name_, seconds(CLOCK_THREAD_CPUTIME_ID) - cpu0_, seconds(CLOCK_MONOTONIC) - wall0_);
}

}  // namespace viper
