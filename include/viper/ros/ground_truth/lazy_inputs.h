// A node's inputs taken only while someone listens to its outputs (the normals and labelled_cloud
// nodes): no subscriber, no subscription, no cost a frame.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <utility>

namespace viper {

class LazyInputs {
 public:
  /// `subscribe` subscribes every input, `unsubscribe` lets them go; each is called under this
  /// object's lock, one at a time.
  LazyInputs(std::function<void()> subscribe, std::function<void()> unsubscribe)
      : subscribe_(std::move(subscribe)), unsubscribe_(std::move(unsubscribe)) {}
  /// Makes the outputs with `advertise` under the lock: their connect callbacks, which may run on
  /// another thread at once, wait in update() until the publishers are there.
  void advertise(const std::function<void()>& advertise) {
    std::lock_guard<std::mutex> lock(mutex_);
    advertise();
  }
  /// From the outputs' connect and disconnect callbacks: `subscribers()` says how many the outputs
  /// have now. Subscribes on the first, lets go after the last.
  void update(const std::function<uint32_t()>& subscribers) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool wanted = subscribers() > 0;
    if (wanted == subscribed_) return;
    subscribed_ = wanted;
    (wanted ? subscribe_ : unsubscribe_)();
  }
  /// Lets the inputs go for good (a node's destructor).
  void stop() {
    std::lock_guard<std::mutex> lock(mutex_);
    unsubscribe_();
    subscribed_ = false;
  }

 private:
  std::function<void()> subscribe_, unsubscribe_;
  std::mutex mutex_;
  bool subscribed_ = false;
};

}  // namespace viper
