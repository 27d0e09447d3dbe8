#include "viper/ros/pacing/pace_gate.h"

#include <chrono>

namespace viper {

std::string readPaceOptions(const ros::NodeHandle& pnh, PaceOptions& o) {
  pnh.param<std::string>("pace_topic", o.topic, "");
  pnh.param("max_in_flight", o.max_in_flight, 2);
  pnh.param("pace_timeout_s", o.timeout_s, 10.0);
  if (o.max_in_flight < 1) return "~max_in_flight must be >= 1, got " + std::to_string(o.max_in_flight);
  if (!(o.timeout_s > 0.0)) return "~pace_timeout_s must be > 0, got " + std::to_string(o.timeout_s);
  return {};
}

PaceGate::PaceGate(ros::NodeHandle nh, const PaceOptions& options, std::string player)
    : options_(options), player_(std::move(player)) {
  if (active()) sub_ = nh.subscribe(options_.topic, 100, &PaceGate::onFinished, this);
}

void PaceGate::onFinished(const std_msgs::HeaderConstPtr& header) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (header->stamp > finished_) finished_ = header->stamp;
    while (!in_flight_.empty() && in_flight_.front() <= finished_) in_flight_.pop_front();
  }
  room_.notify_all();
}

void PaceGate::sent(const ros::Time& stamp) {
  if (!active()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (stamp > finished_ && (in_flight_.empty() || stamp > in_flight_.back())) in_flight_.push_back(stamp);
}

size_t PaceGate::inFlight() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return in_flight_.size();
}

bool PaceGate::waitForRoom(const std::atomic<bool>& stop) {
  if (!active()) return !stop;
  const auto full = [this] { return in_flight_.size() >= static_cast<size_t>(options_.max_in_flight); };
  std::unique_lock<std::mutex> lock(mutex_);
  if (!full()) return !stop;
  ++waits_;
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + std::chrono::duration<double>(options_.timeout_s);
  // Woken by every finished frame; polled for stop.
  while (full() && !stop && ros::ok()) {
    if (std::chrono::steady_clock::now() >= deadline) {
      ROS_WARN_THROTTLE(5.0,
                        "%s: %zu frames sent (the oldest stamped %.6f) and not reported finished on '%s' within "
                        "%.1f s (~pace_timeout_s): sending the next one anyway",
                        player_.c_str(), in_flight_.size(), in_flight_.front().toSec(), sub_.getTopic().c_str(),
                        options_.timeout_s);
      in_flight_.clear();
      break;
    }
    room_.wait_for(lock, std::chrono::milliseconds(100));
  }
  waited_s_ = waited_s_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return !stop;
}

}  // namespace viper
