#include "viper/ros/bridge/capture_bridge.h"

#include "viper/capture/capture_stream.h"
#include "viper/ros/conversions/frame_conversions.h"

#include <rosgraph_msgs/Clock.h>

#include <sys/stat.h>

#include <stdexcept>

namespace viper {

namespace {

constexpr double kPendingPollS = 0.02;
constexpr double kOpenRetryS = 0.5;
constexpr double kThrottleS = 5.0;
// After the last frame, time for subscribers to drain their connections before the node exits.
constexpr double kExitDrainS = 1.0;

bool fileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

}  // namespace

CaptureBridge::CaptureBridge(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
    : nh_(nh), private_nh_(private_nh), it_(nh) {}

CaptureBridge::~CaptureBridge() { stop(); }

bool CaptureBridge::start(bool is_node) {
  is_node_ = is_node;
  auto options = loadCaptureBridgeOptions(private_nh_);
  if (!options) return false;
  options_ = *options;
  if (options_.exit_when_done && !is_node_) {
    ROS_WARN("capture_bridge: ~exit_when_done is ignored in a nodelet (it would end the whole manager)");
    options_.exit_when_done = false;
  }

  if (!options_.follow) {
    // Fail at start-up, not later in the thread, when the file cannot be a capture at all.
    try {
      CaptureReader probe(options_.file);
    } catch (const std::exception& e) {
      ROS_FATAL("capture_bridge: cannot read capture '%s': %s. Check ~file, or set ~follow:=true if the file is "
                "still to be written.",
                options_.file.c_str(), e.what());
      return false;
    }
  }

  const uint32_t q = static_cast<uint32_t>(options_.queue_size);
  color_pub_ = it_.advertise("color/image_raw", q);
  color_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("color/camera_info", q);
  depth_pub_ = it_.advertise("depth/image_raw", q);
  depth_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("depth/camera_info", q);
  draw_ids_pub_ = it_.advertise("draw_ids", q);
  primitive_ids_pub_ = it_.advertise("primitive_ids", q);
  draws_pub_ = nh_.advertise<DrawList>("draws", q);
  mesh_store_pub_ = nh_.advertise<MeshStore>("mesh_store", 1, /*latch=*/true);
  if (options_.publish_clock) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", q);
  gate_ = std::make_unique<PaceGate>(nh_, options_.pace, "capture_bridge");

  stop_ = false;
  thread_ = std::thread(&CaptureBridge::run, this);
  return true;
}

void CaptureBridge::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool CaptureBridge::running() const { return !stop_ && ros::ok(); }

bool CaptureBridge::sleepFor(double seconds) {
  if (seconds > 0.0) {
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return stop_.load(); });
  }
  return running();
}

bool CaptureBridge::waitForSubscribers() {
  bool logged = false;
  while (running()) {
    const bool all = color_pub_.getNumSubscribers() > 0 && color_info_pub_.getNumSubscribers() > 0 &&
                     depth_pub_.getNumSubscribers() > 0 && depth_info_pub_.getNumSubscribers() > 0 &&
                     draw_ids_pub_.getNumSubscribers() > 0 && primitive_ids_pub_.getNumSubscribers() > 0 &&
                     draws_pub_.getNumSubscribers() > 0;
    if (all) return true;
    if (!logged) {
      ROS_INFO("capture_bridge: waiting until every topic under %s has a subscriber (~wait_for_subscribers)",
               nh_.getNamespace().c_str());
      logged = true;
    }
    sleepFor(kPendingPollS);
  }
  return false;
}

bool CaptureBridge::openReader(std::unique_ptr<CaptureReader>& reader) {
  while (running()) {
    if (options_.follow && !fileExists(options_.file)) {
      ROS_INFO_THROTTLE(kThrottleS, "capture_bridge: waiting for '%s' to appear (~follow)", options_.file.c_str());
      sleepFor(kOpenRetryS);
      continue;
    }
    try {
      reader = std::make_unique<CaptureReader>(options_.file);
      return true;
    } catch (const std::exception& e) {
      if (!options_.follow) {
        ROS_ERROR("capture_bridge: cannot read capture '%s': %s", options_.file.c_str(), e.what());
        return false;
      }
      // A writer may not have finished the header yet.
      ROS_WARN_THROTTLE(kThrottleS, "capture_bridge: '%s' not readable yet: %s", options_.file.c_str(), e.what());
      sleepFor(kOpenRetryS);
    }
  }
  return false;
}

void CaptureBridge::run() {
  ReplayTiming timing(options_.rate, options_.start_time);
  bool first_frame = true;
  ros::WallTime wall_start;
  while (running()) {
    if (!publishPass(timing, first_frame, wall_start) || !options_.loop || first_frame) break;
    timing.beginLoop();
  }
  if (!running()) return;
  ROS_INFO("capture_bridge: done with '%s': %lu frames published", options_.file.c_str(),
           static_cast<unsigned long>(frames_published_.load()));
  if (options_.exit_when_done) {
    sleepFor(kExitDrainS);
    ros::requestShutdown();
  }
}

bool CaptureBridge::publishPass(ReplayTiming& timing, bool& first_frame, ros::WallTime& wall_start) {
  std::unique_ptr<CaptureReader> reader;
  if (!openReader(reader)) return false;
  CaptureFrame frame;
  // The images are decompressed straight into the messages they are published in.
  FrameImageMessages images(image_pools_);
  reader->setImageSink(&images);
  int64_t cpu_mark = CpuMeter::threadCpuNs();  // this thread's CPU, reading included, by frame
  while (running()) {
    const uint64_t offset = reader->offset();
    CaptureReader::Status status;
    images.clear();
    try {
      status = reader->next(frame, options_.follow);
    } catch (const CaptureFormatError& e) {
      ROS_ERROR_THROTTLE(kThrottleS,
                         "capture_bridge: capture '%s' is damaged at byte %lu (after %lu published frames): %s. "
                         "Keeping the frames before it; %s",
                         options_.file.c_str(), static_cast<unsigned long>(e.offset()),
                         static_cast<unsigned long>(frames_published_.load()), e.what(),
                         options_.loop ? "starting over" : "stopping");
      return true;
    } catch (const std::exception& e) {
      ROS_ERROR_THROTTLE(kThrottleS, "capture_bridge: reading '%s' at byte %lu failed: %s; stopping",
                         options_.file.c_str(), static_cast<unsigned long>(offset), e.what());
      return false;
    }
    if (status == CaptureReader::Status::kEnd) return true;
    if (status == CaptureReader::Status::kPending) {
      sleepFor(kPendingPollS);
      continue;
    }

    const std::string problem = validateFrame(frame, images.elsewhere());
    if (!problem.empty()) {
      ROS_ERROR_THROTTLE(kThrottleS, "capture_bridge: dropping frame %lu of '%s' (byte %lu): %s",
                         static_cast<unsigned long>(frame.number), options_.file.c_str(),
                         static_cast<unsigned long>(offset), problem.c_str());
      continue;
    }

    if (first_frame) {
      // Subscribers that connect while the bridge waits (nodes launched beside it) miss nothing.
      if (options_.start_delay_s > 0.0 && !sleepFor(options_.start_delay_s)) return false;
      if (options_.wait_for_subscribers && !waitForSubscribers()) return false;
    }
    const double stamp_s = timing.stampOf(frame.time_s);
    if (timing.lastWasClamped()) {
      ROS_WARN_THROTTLE(kThrottleS, "capture_bridge: frame %lu of '%s' goes back in time (%.6f s); stamping it 1 ms "
                        "after the previous frame",
                        static_cast<unsigned long>(frame.number), options_.file.c_str(), frame.time_s);
    }
    if (first_frame) {
      wall_start = ros::WallTime::now();
      first_frame = false;
    } else {
      const double wait_s = timing.dueAfterStart(stamp_s) - (ros::WallTime::now() - wall_start).toSec();
      if (!sleepFor(wait_s)) return false;
    }
    if (!gate_->waitForRoom(stop_)) return false;
    publishFrame(frame, images, stamp_s);
    gate_->sent(ros::Time(stamp_s));
    const int64_t now = CpuMeter::threadCpuNs();
    cpu_.add(now - cpu_mark, true);
    cpu_mark = now;
  }
  return false;
}

void CaptureBridge::publishFrame(const CaptureFrame& frame, const FrameImageMessages& images, double stamp_s) {
  std_msgs::Header header;
  header.stamp = ros::Time(stamp_s);
  header.frame_id = options_.frame_id;

  try {
    const FrameMessages m = frameMessages(frame, header, mesh_store_, image_pools_, images);
    if (!m.camera_problem.empty()) {
      ROS_WARN_THROTTLE(kThrottleS, "capture_bridge: frame %lu of '%s': %s", static_cast<unsigned long>(frame.number),
                        options_.file.c_str(), m.camera_problem.c_str());
    }
    // The clock first, so sim-time subscribers see the frame's time when its messages arrive.
    if (options_.publish_clock) {
      rosgraph_msgs::Clock clock;
      clock.clock = header.stamp;
      clock_pub_.publish(clock);
    }
    if (m.mesh_store) mesh_store_pub_.publish(m.mesh_store);
    color_pub_.publish(m.color);
    color_info_pub_.publish(m.camera_info);
    depth_pub_.publish(m.depth);
    depth_info_pub_.publish(m.camera_info);
    draw_ids_pub_.publish(m.draw_ids);
    primitive_ids_pub_.publish(m.primitive_ids);
    draws_pub_.publish(m.draws);
    ++frames_published_;
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(kThrottleS, "capture_bridge: dropping frame %lu of '%s': %s",
                       static_cast<unsigned long>(frame.number), options_.file.c_str(), e.what());
  }
}

}  // namespace viper
