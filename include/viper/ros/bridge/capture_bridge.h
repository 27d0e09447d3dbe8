// capture_bridge: publishes a capture stream (.vcap, optionally followed while it is written) as raw
// ROS topics. Topics and parameters are documented in docs/capture_bridge.md.
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/measurement/cpu_meter.h"
#include "viper/ros/pacing/pace_gate.h"
#include "viper/ros/pacing/replay_timing.h"

#include <image_transport/image_transport.h>
#include <ros/ros.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace viper {

class CaptureReader;

/// Settings of the bridge, read from the private node handle (see loadCaptureBridgeOptions()).
struct CaptureBridgeOptions {
  std::string file;                   ///< ~file (required): path of the .vcap capture
  bool follow = false;                ///< ~follow: keep reading a file that is still being written
  double rate = 1.0;                  ///< ~rate: speed factor over capture time; 0 = as fast as possible
  bool wait_for_subscribers = false;  ///< ~wait_for_subscribers: start once every topic has a subscriber
  double start_delay_s = 0.0;         ///< ~start_delay_s: wait this long after advertising (like rosbag --delay)
  bool loop = false;                  ///< ~loop: start over at the end (not with follow)
  bool publish_clock = false;         ///< ~publish_clock: publish /clock from the frame stamps
  std::optional<double> start_time;   ///< ~start_time: stamp of the first frame, seconds
  std::string frame_id = "camera_optical";  ///< ~frame_id of every header
  int queue_size = 10;                ///< ~queue_size of every publisher
  bool exit_when_done = false;        ///< ~exit_when_done: (node only) shut down after the last frame
  PaceOptions pace;                   ///< ~pace_topic, ~max_in_flight, ~pace_timeout_s: back-pressure (pace_gate.h)
};

/// Reads and validates the options once: impossible settings log ROS_FATAL with how to fix them and
/// return nullopt; wrong ones log an error and fall back to the default; questionable ones warn.
std::optional<CaptureBridgeOptions> loadCaptureBridgeOptions(const ros::NodeHandle& private_nh);

/// The bridge: owns the publishers and a publishing thread. Used by the node and the nodelet.
class CaptureBridge {
 public:
  /// Topics are advertised in `nh`'s namespace; parameters come from `private_nh`.
  CaptureBridge(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Stops and joins the publishing thread.
  ~CaptureBridge();
  CaptureBridge(const CaptureBridge&) = delete;
  CaptureBridge& operator=(const CaptureBridge&) = delete;

  /// Validates the parameters, opens the capture and starts publishing. Returns false (after a
  /// ROS_FATAL saying how to fix it) when the configuration is impossible.
  /// `is_node`: whether the bridge may shut the process down (~exit_when_done).
  bool start(bool is_node);
  /// Stops publishing; returns once the thread has ended. Idempotent.
  void stop();
  /// Frames published so far.
  uint64_t framesPublished() const { return frames_published_; }

 private:
  void run();
  /// One pass over the capture; returns false if the bridge should not loop again.
  bool publishPass(ReplayTiming& timing, bool& first_frame, ros::WallTime& wall_start);
  void publishFrame(const CaptureFrame& frame, const FrameImageMessages& images, double stamp_s);
  bool openReader(std::unique_ptr<CaptureReader>& reader);
  bool waitForSubscribers();
  /// Sleeps up to `seconds` of wall time; returns false if stop was requested meanwhile.
  bool sleepFor(double seconds);
  bool running() const;

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  CaptureBridgeOptions options_;
  bool is_node_ = true;

  image_transport::ImageTransport it_;
  image_transport::Publisher color_pub_, depth_pub_, draw_ids_pub_, primitive_ids_pub_;
  ros::Publisher color_info_pub_, depth_info_pub_, draws_pub_, mesh_store_pub_, clock_pub_;

  MeshStoreAccumulator mesh_store_;
  FrameImagePools image_pools_;  // the images' messages, recycled
  std::unique_ptr<PaceGate> gate_;
  CpuMeter cpu_{"capture_bridge", private_nh_};  // its thread's CPU a frame (cpu_meter.h)

  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> frames_published_{0};
};

}  // namespace viper
