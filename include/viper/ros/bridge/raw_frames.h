// The raw frames of a lockstep run (generate), without a ROS master: from a capture (.vcap),
// converted exactly as capture_bridge and capture_to_bag convert it, or from a raw bag (written by
// capture_to_bag, make_test_bag.sh or `rosbag record` of the bridge).
#pragma once

#include "viper/capture/capture_stream.h"
#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/bridge/bag_writer.h"
#include "viper/ros/pacing/replay_timing.h"
#include "viper/ros/conversions/frame_conversions.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// A source of raw frames, each as the bridge's messages of one stamp.
class RawFrames {
 public:
  virtual ~RawFrames() = default;
  /// The next frame; false at the end. A damaged input ends the frames with a problem (problems())
  /// after every intact frame before the damage. Throws std::runtime_error only for a failure that
  /// is not the input's (e.g. out of memory).
  virtual bool next(FrameMessages& out) = 0;
  /// Frames in the input, when known in advance (for a progress bar); 0 otherwise.
  virtual uint64_t frameCount() const = 0;
  /// What was wrong (frames dropped, damage), each naming the file and where.
  const std::vector<std::string>& problems() const { return problems_; }
  /// What is worth saying but lost nothing (no camera for camera_info, a capture time that goes
  /// back and was stamped after the previous frame).
  const std::vector<std::string>& warnings() const { return warnings_; }

 protected:
  std::vector<std::string> problems_, warnings_;
};

/// A capture's frames: stamps as the bridge stamps a file replay (ReplayTiming at rate 0), header
/// frame id `frame_id`, frames the bridge would drop (validateFrame) dropped with a problem.
class CaptureRawFrames : public RawFrames {
 public:
  /// Throws std::runtime_error naming the file if it cannot be opened or its header is damaged.
  CaptureRawFrames(const std::string& path, std::optional<double> start_time_s = std::nullopt,
                   const std::string& frame_id = "camera_optical");
  bool next(FrameMessages& out) override;
  uint64_t frameCount() const override { return 0; }
  /// The number of the last frame returned, if any.
  std::optional<uint64_t> lastNumber() const { return last_number_; }
  /// Frames returned so far.
  uint64_t framesRead() const { return frames_; }

 private:
  std::string path_;
  std::unique_ptr<CaptureReader> reader_;
  ReplayTiming timing_;
  std::string frame_id_;
  MeshStoreAccumulator meshes_;
  FrameImagePools pools_;  // the images' messages, recycled once whoever took them lets go
  CaptureFrame frame_;
  std::optional<uint64_t> last_number_;
  uint64_t frames_ = 0;
  bool camera_warned_ = false, ended_ = false;
};

/// A raw bag's frames: the messages of NS/draws, NS/draw_ids, NS/depth/image_raw, NS/primitive_ids,
/// NS/color/image_raw and NS/color/camera_info of one header stamp, with NS/mesh_store when that
/// stamp brought one; a stamp missing any of them is dropped with a problem. Messages of neighbouring
/// frames may interleave (a `rosbag record` of the bridge): a frame is taken once two later frames
/// are whole.
class BagRawFrames : public RawFrames {
 public:
  /// Throws std::runtime_error naming the bag if it cannot be opened or has no NS/draws.
  explicit BagRawFrames(const std::string& path, const std::string& ns = "/capture");
  bool next(FrameMessages& out) override;
  uint64_t frameCount() const override { return frame_count_; }

 private:
  bool complete(const FrameMessages& m) const;
  /// Takes the oldest pending stamp: true with `out` if it is a whole frame, else a problem.
  bool takeOldest(FrameMessages& out);

  std::string path_, ns_;
  std::unique_ptr<BagReader> bag_;  // null once read to its end (or its damage)
  BagReadMessage m_;
  std::map<ros::Time, FrameMessages> pending_;
  uint64_t frame_count_ = 0;
};

/// Writes a raw frame's messages under `ns` (e.g. "/capture") in the bridge's publication order, as
/// a recorder of the bridge would (capture_to_bag, generate's ground-truth bags).
void writeRawFrame(BagWriter& bag, const std::string& ns, const FrameMessages& m);

/// A .vcap path gives CaptureRawFrames, anything else BagRawFrames.
std::unique_ptr<RawFrames> openRawFrames(const std::string& path);

}  // namespace viper
