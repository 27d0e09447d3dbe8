// One sequence of a dataset, generated in lockstep without a ROS master: raw frames (a capture or a
// raw bag), each decoded once, through every ground-truth step (the core GroundTruthPipeline, the
// nodes' own code) into VIPER's release layout and/or a ground-truth bag (its messages made as the
// nodes make them, ground_truth_conversions.h). Every frame is processed; nothing is dropped for being
// slow. The sequence is written into a temporary folder and moved into place with a done-marker
// (sha256 of every file) only when complete, so a partial sequence is never taken for a finished
// one. docs/dataset_generation.md.
#pragma once

#include "viper/ground_truth/ground_truth_pipeline.h"
#include "viper/ground_truth/stage_times.h"
#include "viper/ros/bridge/raw_frames.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/dataset/viper_exporter.h"

#include <filesystem>
#include <functional>
#include <string>

namespace viper {

/// What a sequence writes.
struct SequenceOutputs {
  bool layout = true;  ///< VIPER's release layout: img, cls, inst, flow, flowbw, bb, camera
  bool bag = true;     ///< SPLIT/bag/SEQ.bag: raw and ground-truth topics at their header stamps
  /// The formats training frameworks read (docs/training_formats.md), under SPLIT/training/SEQ/:
  /// cityscapes/ (gtFine, leftImg8bit), coco/ (visible and amodal instances), kitti/ (flow, depth).
  bool cityscapes = false, coco = false, kitti = false;
  std::string bag_compression = "lz4";
};

struct SequenceSettings {
  std::string root;            ///< the dataset's root folder
  std::string split = "train";
  std::string seq = "001";
  SequenceOutputs outputs;
  ViperExportOptions layout;   ///< image format, palette, ... (root, split and seq are set from above)
  GroundTruthSettings ground_truth;
  OdometrySettings odometry;   ///< the frames of the bag's poses and boxes (map, camera)
  uint64_t max_frames = 0;     ///< 0 = every frame of the input
};

/// What generating a sequence did.
struct SequenceResult {
  uint64_t frames = 0;           ///< frames processed and written
  uint64_t dropped = 0;          ///< frames a step dropped (bad input), named in problems
  std::vector<std::string> problems;  ///< errors: input damage, dropped frames or data, each naming the input and frame
  std::vector<std::string> warnings;  ///< what a node would warn about (an object without a box, ...)
  bool skipped = false;          ///< already finished (its marker checked out); nothing was done
  std::filesystem::path marker;  ///< the done-marker
  uint64_t files = 0;                ///< files the marker lists
  uint64_t checksums_read_back = 0;  ///< of those, read for their checksum (the others' came from their writers)
  StageTimes stages;             ///< CPU and wall time of reading, each step and each writer
};

class SequenceGenerator {
 public:
  explicit SequenceGenerator(SequenceSettings settings, LabelTable labels, ClassTable classes);

  /// The marker of the sequence: ROOT/SPLIT/SEQ.done.
  std::filesystem::path markerPath() const;
  /// Whether the sequence is finished: its marker exists and every file has its checksum.
  bool finished(std::string* why_not = nullptr) const;

  /// Generates the sequence from `input` (unless finished() and !force). `progress(done, total)`
  /// is called after every frame (total 0 when unknown). Throws std::runtime_error naming the
  /// sequence, the frame and the file when an output cannot be written; the partial sequence is
  /// then left in ROOT/.partial and never counts as finished.
  SequenceResult run(RawFrames& input, bool force, const std::function<void(uint64_t, uint64_t)>& progress = {});

 private:
  SequenceSettings settings_;
  LabelTable labels_;
  ClassTable classes_;
};

}  // namespace viper
