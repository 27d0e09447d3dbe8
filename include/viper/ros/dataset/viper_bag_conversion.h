// Batch conversion of VIPER's release layout into a bag: the player's messages, topics and stamps,
// written with the package's BagWriter as fast as the files can be read. The viper_to_bag command
// and bench_viper_layout use it. docs/viper_layout.md.
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/ros/dataset/viper_layout_conversions.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace viper {

/// What to convert and how.
struct ViperToBagOptions {
  std::string root;                    ///< the layout's root folder
  std::string split;                   ///< "" = the root's only split (else "train" if present)
  std::vector<std::string> sequences;  ///< empty = every sequence of the split, in name order
  std::set<dataset::ViperModality> modalities = {dataset::ViperModality::kImg,  dataset::ViperModality::kCls,
                                                 dataset::ViperModality::kInst, dataset::ViperModality::kFlow,
                                                 dataset::ViperModality::kFlowBw, dataset::ViperModality::kBb};
  bool camera = true;                  ///< read the camera files (odom, tf, camera_info, boxes in map)
  double fps = 15.0;                   ///< frame n of a sequence is n / fps seconds after its frame 0
  std::optional<double> start_time;    ///< stamp of the first frame (s); default as the player's
  ViperTfFrames frames;
  std::string compression = "none";    ///< "none", "lz4" or "bz2"
  bool semantic_color = false;         ///< also write ground_truth/semantic_color (needs `classes`)
  const ClassTable* classes = nullptr; ///< class names of boxes, colors of semantic_color
  /// Frames read ahead by a second thread while the current one is written (0 = read in line).
  int prefetch = 2;
};

/// What a conversion did.
struct ViperToBagStats {
  size_t sequences = 0;
  size_t frames = 0;
  size_t messages = 0;
  uint64_t message_bytes = 0;  ///< serialized size of every message written
  size_t problems = 0;         ///< problems reported (files left out, bad lines, missing frames)
};

/// Called with each problem, a message that names the file.
using ProblemCallback = std::function<void(const std::string&)>;
/// Called after each frame: frames done, frames in all.
using ProgressCallback = std::function<void(size_t, size_t)>;

/// Converts the layout at options.root into the bag `bag_path` (replaced). Topics are the player's
/// under "/" (/capture/color/image_raw, /ground_truth/semantic, ...), plus /tf (map -> body per
/// frame) and /tf_static (body -> optical, latched); each message's bag time is its header stamp.
/// Bad files are reported through `problem` and left out; the rest is written. Throws
/// std::runtime_error if the root, split or a sequence does not exist, nothing is there to
/// convert, or the bag cannot be written.
ViperToBagStats convertViperToBag(const ViperToBagOptions& options, const std::string& bag_path,
                                  const ProblemCallback& problem, const ProgressCallback& progress);

/// The split a player or converter uses when none is given: the root's only split, else "train"
/// if present, else "". Throws std::runtime_error if `root` is not a folder.
std::string defaultViperSplit(const std::string& root);

}  // namespace viper
