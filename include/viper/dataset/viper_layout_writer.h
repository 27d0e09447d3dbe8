// Writes ground truth into VIPER's release layout, frame by frame, from core types: camera images
// (img), class ids (cls), instance images (inst), forward and backward flow (flow, flowbw), boxes
// (bb) and the sequence's camera file. The parts of a frame may come in any order; those that need a
// partner (inst from class ids + instance ids, bb from boxes + 2D boxes, camera rows from a pose +
// intrinsics) wait until it comes or the frame is flushed. `generate` hands it the ground-truth
// pipeline's results; export_viper and the viper_exporter node hand it messages through
// ViperExporter (src/ros/dataset/viper_exporter.cpp), which converts them. docs/viper_layout.md.
#pragma once

#include "viper/dataset/file_digests.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"
#include "viper/dataset/viper_images.h"
#include "viper/dataset/write_queue.h"
#include "viper/dataset/zip_archive.h"
#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/boxes_step.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/instance_pipeline.h"

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
  kDraws,     ///< the frame's draws: the program's own view and projection matrices (addCamera)
  kOdometry,  ///< the camera body's pose (addOdometry) + intrinsics (addCameraInfo; near/far assumed)
  kNone,      ///< no camera file
};

/// Which inputs will come at all, so that a part waits only for partners that exist.
struct ViperExportInputs {
  bool semantic = true;          ///< class ids + instance ids make inst
  bool instance_ids = true;
  bool instances_viper = false;  ///< inst comes ready-made: class ids and instance ids need not wait
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
  /// written (generate's done-marker then reads none of them back). Must outlive the writer.
  dataset::FileDigests* digests = nullptr;
};

/// Files written, per modality, and parts skipped.
struct ViperExportStats {
  size_t img = 0, cls = 0, inst = 0, flow = 0, flowbw = 0, bb = 0, camera_rows = 0;
  size_t skipped = 0;         ///< bad messages (parts that could not be read)
  size_t flow_overflowed = 0; ///< flow values that became inf in float16 (>= 65520 px)
};

/// One box of bb: an object's oriented box in the camera optical frame, its class and instance id.
struct ViperBox {
  OrientedBox in_optical;
  int class_id = 0;
  int32_t id = 0;
};

/// The boxes step's boxes in the optical frame (FrameBoxes::has_optical) for bb, each with its track
/// id. The orientation goes through its rotation matrix, as in a box message read back
/// (fromBox3DMsg), so that bb holds the same numbers whether the boxes come as messages or not.
std::vector<ViperBox> viperBoxes(const FrameBoxes& boxes);

/// 2D boxes of bb by instance id: x_min, y_min, x_max, y_max (inclusive pixels).
using Boxes2d = std::map<int32_t, std::array<double, 4>>;
/// The 2D boxes of the instances step's objects: each tracked object's (track id > 0) tight box of
/// its visible pixels, for those with any.
Boxes2d objectBoxes2d(const std::vector<TrackedObject>& objects);

/// Whoever keeps an image's pixels alive and unchanged while the writer needs them (a message, say:
/// the writer threads encode them later). Null: the writer copies them before add* returns.
using PixelOwner = std::shared_ptr<const void>;

class ViperLayoutWriter {
 public:
  /// Checks the names (throws std::invalid_argument like viperFramePath) and creates nothing yet.
  explicit ViperLayoutWriter(const ViperExportOptions& options);

  // Each add* takes one part of frame `frame`. It returns "" or what is wrong with it, which is
  // then skipped (counted in stats().skipped). It throws std::runtime_error naming the file if a
  // file cannot be written. Images are packed rows, their pixels at the pointers, held by `owner`.

  /// RGB camera image (3 channels) -> img.
  std::string addColor(uint64_t frame, const dataset::ImageView8& rgb, PixelOwner owner);
  /// Class ids (1 channel) -> cls; also half of inst when instances_viper does not come.
  std::string addSemantic(uint64_t frame, const dataset::ImageView8& class_ids, PixelOwner owner);
  /// Instance ids (width * height) -> the other half of inst; also the 2D boxes of bb when no
  /// objects come.
  std::string addInstanceIds(uint64_t frame, const int32_t* ids, uint32_t width, uint32_t height, PixelOwner owner);
  /// VIPER instance image (3 channels) -> inst, as it is.
  std::string addInstancesViper(uint64_t frame, const dataset::ImageView8& rgb, PixelOwner owner);
  /// Flow (width * height (u, v) pairs) -> flow (forward) or flowbw (backward).
  std::string addFlow(uint64_t frame, const float* uv, uint32_t width, uint32_t height, PixelOwner owner,
                      bool backward);
  /// Boxes in the camera optical frame -> bb.
  std::string addBoxesOptical(uint64_t frame, std::vector<ViperBox> boxes);
  /// The objects' 2D boxes (objectBoxes2d), for bb.
  std::string addObjects(uint64_t frame, Boxes2d boxes_2d);
  /// CameraSource::kDraws: the frame's camera (chooseFrameCamera; none: skipped) -> a camera row.
  std::string addCamera(uint64_t frame, const std::optional<FrameCamera>& camera);
  /// CameraSource::kOdometry: the camera body's pose in the map (half of a camera row).
  std::string addOdometry(uint64_t frame, const Eigen::Isometry3d& map_from_body);
  /// CameraSource::kOdometry: the intrinsics (camera_info's K, row by row) of a `width` x `height`
  /// image (the other half).
  std::string addCameraInfo(uint64_t frame, const std::array<double, 9>& K, uint32_t width, uint32_t height);
  /// Counts a part that could not be read at all (stats().skipped) and returns `problem`.
  std::string skip(const std::string& problem);

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
  struct Image {
    dataset::ImageView8 view;
    PixelOwner owner;
  };
  struct Ids {
    const int32_t* ids = nullptr;
    uint32_t width = 0, height = 0;
    PixelOwner owner;
  };
  struct Intrinsics {
    std::array<double, 9> K;
    uint32_t width, height;
  };
  struct Pending {
    std::optional<Image> semantic;  // until inst is written
    std::optional<Ids> instance_ids;
    bool inst_written = false;
    std::optional<Boxes2d> id_boxes;  // 2D boxes of the instance ids
    std::optional<std::vector<ViperBox>> boxes;
    std::optional<Boxes2d> objects;
    std::optional<Eigen::Isometry3d> map_from_body;
    std::optional<Intrinsics> camera_info;
    bool camera_written = false;
    bool boxes_written = false;
  };
  /// The image, held by `owner`, or a copy held by itself.
  static Image held(const dataset::ImageView8& view, PixelOwner owner);
  std::string path(const char* modality, uint64_t frame, const char* extension);
  void ensureFolder(const char* modality);
  /// Writes what the frame's parts so far complete (inst, bb) and lets go of what is no longer
  /// needed; returns a note or "".
  std::string complete(uint64_t frame, Pending& p);
  std::string writeInstFromParts(uint64_t frame, Pending& p);
  std::string writeBoxes(uint64_t frame, Pending& p);
  std::string writeCameraRow(uint64_t frame, const dataset::RowMajor4& view, const dataset::RowMajor4& projection);
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
