// Writes ground-truth messages into VIPER's release layout, frame by frame: camera images (img),
// class ids (cls), instance images (inst), forward and backward flow (flow, flowbw), boxes (bb)
// and the sequence's camera file. Shared by export_viper's bag and live modes. Messages of one frame
// may come in any order; those that need a partner (inst from semantic + instance ids, bb from boxes
// + 2D boxes, camera rows from odometry + camera_info) wait until it comes or the frame is flushed.
// docs/viper_layout.md.
#pragma once

#include "viper/dataset/file_digests.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"
#include "viper/dataset/viper_images.h"
#include "viper/dataset/write_queue.h"
#include "viper/dataset/zip_archive.h"

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <Eigen/Geometry>

#include <array>
#include <atomic>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// Where camera rows come from.
enum class CameraSource {
  kDraws,     ///< the raw draw list (viper/DrawList): the program's own view and projection matrices
  kOdometry,  ///< nav_msgs/Odometry (map -> camera body) + camera_info (intrinsics; near/far assumed)
  kNone,      ///< no camera file
};

/// Which inputs will come at all, so that a message waits only for partners that exist.
struct ViperExportInputs {
  bool semantic = true;          ///< semantic + instance ids make inst
  bool instance_ids = true;
  bool instances_viper = false;  ///< inst comes ready-made: semantic and instance ids need not wait
  bool objects = true;           ///< 2D boxes of bb; without objects, the instance ids' boxes are used
};

/// Settings of an export.
struct ViperExportOptions {
  std::string root;           ///< the layout's root folder (created)
  std::string split = "train";
  std::string seq = "001";    ///< no '/', no '_'
  std::string image_extension = "png";  ///< img files: "png" (lossless) or "jpg"
  dataset::ImageWriteOptions images;
  dataset::ZipWriteOptions zip;          ///< flow .npz
  dataset::ClassPalette palette;         ///< cls palette (class colors); empty = grayscale PNG
  CameraSource camera = CameraSource::kDraws;
  bool relative_poses = true;  ///< VIPER: view matrices relative to the first exported frame
  double near_m = 0.1;         ///< kOdometry: depth range of the projection written
  double far_m = 1000.0;
  ViperExportInputs inputs;
  /// Threads that encode and write img, cls, inst, flow and flowbw files while the caller goes on
  /// (0: each file is written inside its add* call). Errors then come from a later add*, flushUpTo
  /// or finish, still naming the file; notes (flow overflow) from flushUpTo/finish.
  unsigned writer_threads = 0;
  /// When set, every file is recorded there with its SHA-256, taken from its bytes as they are
  /// written (generate's done-marker then reads none of them back). Must outlive the exporter.
  dataset::FileDigests* digests = nullptr;
};

/// Files written, per modality, and messages skipped.
struct ViperExportStats {
  size_t img = 0, cls = 0, inst = 0, flow = 0, flowbw = 0, bb = 0, camera_rows = 0;
  size_t skipped = 0;         ///< bad messages
  size_t flow_overflowed = 0; ///< flow values that became inf in float16 (>= 65520 px)
};

class ViperExporter {
 public:
  /// Checks the names (throws std::invalid_argument like viperFramePath) and creates nothing yet.
  explicit ViperExporter(const ViperExportOptions& options);

  // Each add* takes one message of frame `frame`. It returns "" or what is wrong with the message,
  // which is then skipped (counted in stats().skipped). It throws std::runtime_error naming the
  // file if a file cannot be written.

  /// rgb8 (or bgr8) camera image -> img.
  std::string addColor(uint64_t frame, const sensor_msgs::Image& msg);
  /// mono8 class ids -> cls; also half of inst when instances_viper does not come.
  std::string addSemantic(uint64_t frame, const sensor_msgs::ImageConstPtr& msg);
  /// 32SC1 instance ids -> the other half of inst; also the 2D boxes of bb when no objects come.
  std::string addInstanceIds(uint64_t frame, const sensor_msgs::ImageConstPtr& msg);
  /// rgb8 VIPER instance image -> inst, as it is.
  std::string addInstancesViper(uint64_t frame, const sensor_msgs::Image& msg);
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
  std::vector<std::string> flushUpTo(uint64_t frame);
  /// flushUpTo every frame and closes the camera file.
  std::vector<std::string> finish();

  ViperExportStats stats() const;
  /// CPU seconds the writer threads spent writing files so far (0 without writer threads).
  double writerCpuSeconds() const { return writes_ ? writes_->workerCpuSeconds() : 0.0; }
  const ViperExportOptions& options() const { return options_; }

 private:
  struct Pending {
    sensor_msgs::ImageConstPtr semantic, instance_ids;  // until inst is written
    bool inst_written = false;
    std::optional<std::map<int32_t, std::array<double, 4>>> id_boxes;  // 2D boxes of the instance ids
    Box3DArray::ConstPtr boxes;
    ObjectArray::ConstPtr objects;
    std::optional<Eigen::Isometry3d> map_from_body;
    std::optional<sensor_msgs::CameraInfo> camera_info;
    bool camera_written = false;
    bool boxes_written = false;
  };
  std::string path(const char* modality, uint64_t frame, const char* extension);
  void ensureFolder(const char* modality);
  /// Writes what the frame's messages so far complete (inst, bb) and lets go of what is no longer
  /// needed; returns a note or "".
  std::string complete(uint64_t frame, Pending& p);
  std::string writeInstFromParts(uint64_t frame, Pending& p);
  std::string writeBoxes(uint64_t frame, Pending& p);
  std::string writeCameraRow(uint64_t frame, const dataset::RowMajor4& view, const dataset::RowMajor4& projection);
  std::string skip(const std::string& problem);
  /// Runs a job that writes one file of `frame` now, or queues it with writer threads.
  std::string write(uint64_t frame, dataset::WriteQueue::Job job);

  ViperExportOptions options_;
  ViperExportStats stats_;
  std::map<uint64_t, Pending> pending_;
  std::map<std::string, bool> folders_;
  std::optional<dataset::RowMajor4> origin_view_;
  std::ofstream camera_file_;
  std::string camera_path_;
  std::unique_ptr<dataset::Sha256> camera_digest_;  // with options_.digests: the camera file so far
  uint64_t camera_bytes_ = 0;
  std::atomic<size_t> flow_overflowed_{0};
  std::unique_ptr<dataset::WriteQueue> writes_;  // null without writer threads
};

}  // namespace viper
