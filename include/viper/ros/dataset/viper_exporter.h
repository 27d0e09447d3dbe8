// Writes ground-truth messages into VIPER's release layout, frame by frame: each message converted
// to the core types of ViperLayoutWriter (include/viper/dataset/viper_layout_writer.h), which writes
// camera images (img), class ids (cls), instance images (inst), forward and backward flow (flow,
// flowbw), boxes (bb) and the sequence's camera file. Shared by export_viper's bag and live modes
// and the viper_exporter node; `generate` hands its core results to the writer itself (writer()).
// Images are read where they are (the message is held until its file is written) when their rows
// are packed, else copied. docs/viper_layout.md.
#pragma once

#include "viper/dataset/viper_layout_writer.h"

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <string>
#include <vector>

namespace viper {

class ViperExporter {
 public:
  /// Checks the names (throws std::invalid_argument like viperFramePath) and creates nothing yet.
  explicit ViperExporter(const ViperExportOptions& options) : writer_(options) {}

  // Each add* takes one message of frame `frame`. It returns "" or what is wrong with the message,
  // which is then skipped (counted in stats().skipped). It throws std::runtime_error naming the
  // file if a file cannot be written.

  /// rgb8 (or bgr8) camera image -> img (copied).
  std::string addColor(uint64_t frame, const sensor_msgs::Image& msg);
  /// The same, read in the message, which is held until its file is written.
  std::string addColor(uint64_t frame, const sensor_msgs::ImageConstPtr& msg);
  /// mono8 class ids -> cls; also half of inst when instances_viper does not come.
  std::string addSemantic(uint64_t frame, const sensor_msgs::ImageConstPtr& msg);
  /// 32SC1 instance ids -> the other half of inst; also the 2D boxes of bb when no objects come.
  std::string addInstanceIds(uint64_t frame, const sensor_msgs::ImageConstPtr& msg);
  /// rgb8 VIPER instance image -> inst, as it is (copied).
  std::string addInstancesViper(uint64_t frame, const sensor_msgs::Image& msg);
  /// The same, read in the message, which is held until its file is written.
  std::string addInstancesViper(uint64_t frame, const sensor_msgs::ImageConstPtr& msg);
  /// 32FC2 flow -> flow (forward) or flowbw (backward).
  std::string addFlow(uint64_t frame, const sensor_msgs::ImageConstPtr& msg, bool backward);
  /// Boxes in the camera optical frame (the boxes node's boxes_optical) -> bb.
  std::string addBoxesOptical(uint64_t frame, const Box3DArray::ConstPtr& msg);
  /// Objects with their 2D boxes (the instances node's objects), for bb.
  std::string addObjects(uint64_t frame, const ObjectArray::ConstPtr& msg);
  /// CameraSource::kDraws: the frame's view and projection matrices -> a camera row.
  std::string addDraws(uint64_t frame, const DrawList& msg);
  /// CameraSource::kOdometry: the camera body pose (half of a camera row).
  std::string addOdometry(uint64_t frame, const nav_msgs::Odometry& msg);
  /// CameraSource::kOdometry: the intrinsics (the other half).
  std::string addCameraInfo(uint64_t frame, const sensor_msgs::CameraInfo& msg);

  /// Completes the frames up to `frame` with what they have (inst, bb, camera rows whose partner
  /// never came) and forgets them. Returns notes about what could not be completed.
  std::vector<std::string> flushUpTo(uint64_t frame) { return writer_.flushUpTo(frame); }
  /// flushUpTo every frame and closes the camera file.
  std::vector<std::string> finish() { return writer_.finish(); }

  ViperExportStats stats() const { return writer_.stats(); }
  /// CPU seconds the writer threads spent writing files so far (0 without writer threads).
  double writerCpuSeconds() const { return writer_.writerCpuSeconds(); }
  const ViperExportOptions& options() const { return writer_.options(); }
  /// The writer on core types the messages go to.
  ViperLayoutWriter& writer() { return writer_; }

 private:
  ViperLayoutWriter writer_;
};

}  // namespace viper
