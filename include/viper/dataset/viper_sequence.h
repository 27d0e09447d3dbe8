// A sequence of VIPER's release layout as a whole: which files it has, and reading one frame of
// every modality at once, leaving out (and naming) whatever is damaged so the rest can still be
// used. Layout: `<root>/<split>/<modality>/<seq>/<seq>_<frame:05d>.<ext>` and
// `<root>/<split>/camera/<seq>.csv`; docs/viper_layout.md.
#pragma once

#include "viper/dataset/flow_image.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"
#include "viper/dataset/viper_images.h"

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace viper::dataset {

/// The modalities stored as one file per frame.
enum class ViperModality { kImg, kCls, kInst, kFlow, kFlowBw, kBb };

/// Every per-frame modality, in the order frames are read.
const std::vector<ViperModality>& allViperModalities();
/// Folder name: "img", "cls", "inst", "flow", "flowbw", "bb".
const char* viperModalityName(ViperModality modality);
/// The modality of a folder name; nullopt for others (including "camera").
std::optional<ViperModality> viperModalityFromName(const std::string& name);

/// The files of one sequence, found by scanViperSequence.
struct ViperSequenceFiles {
  std::string root, split, seq;
  /// Per modality: frame number -> path. img prefers .png over .jpg / .jpeg for the same frame.
  std::map<ViperModality, std::map<uint64_t, std::string>> files;
  std::string camera_csv;  ///< path of `<split>/camera/<seq>.csv`, empty if there is none
  /// Files of the sequence's folders that were not used, each with the reason (wrong name,
  /// extension, another sequence's prefix, a duplicate).
  std::vector<std::string> problems;

  bool has(ViperModality m) const { return files.count(m) != 0 && !files.at(m).empty(); }
};

/// Splits under `root`: sub-folders holding at least one modality folder or a camera folder,
/// sorted. Throws std::runtime_error naming `root` if it is not a readable folder.
std::vector<std::string> listViperSplits(const std::string& root);

/// Sequences of a split: the sub-folders of its modality folders and the `camera/<seq>.csv` files,
/// sorted. Empty if the split does not exist.
std::vector<std::string> listViperSequences(const std::string& root, const std::string& split);

/// Finds every file of one sequence. Never throws for unusable files (see `problems`).
ViperSequenceFiles scanViperSequence(const std::string& root, const std::string& split, const std::string& seq);

/// The sequence's frame numbers, ascending: every frame that has a file of any modality or a row
/// of `camera`.
std::vector<uint64_t> viperSequenceFrames(const ViperSequenceFiles& files,
                                          const std::map<uint64_t, ViperCameraRow>& camera);

/// Messages about frames that are missing: frame numbers absent from every modality inside the
/// sequence's range, and per modality the frames it lacks that others have (flow is not expected
/// for the last frame, flowbw not for the first). Each message names the folder or file.
std::vector<std::string> describeMissingFrames(const ViperSequenceFiles& files,
                                               const std::map<uint64_t, ViperCameraRow>& camera,
                                               const std::vector<uint64_t>& frames);

/// Everything read for one frame; a modality is empty if its file is absent, unreadable or of the
/// wrong size.
struct ViperFrame {
  uint64_t frame = 0;
  uint32_t width = 0;   ///< size of the frame's images, 0 if none was read
  uint32_t height = 0;
  std::optional<Image8> img;   ///< RGB
  std::optional<Image8> cls;   ///< class ids, 1 channel
  std::optional<Image8> inst;  ///< RGB, R = class, 256 * G + B = instance
  std::optional<FlowImage> flow;    ///< forward flow, frame -> frame + 1
  std::optional<FlowImage> flowbw;  ///< backward flow, frame -> frame - 1
  std::optional<std::vector<ViperBoxRow>> boxes;
  std::optional<ViperCameraRow> camera;
};

/// Reads frame `frame` of every modality in `wanted` that `files` has, plus its camera row. A file
/// that cannot be read (missing, truncated, corrupt, wrong kind) is left out; so is an image or
/// flow whose size differs from the frame's size, which is the size most of the frame's images and
/// flows agree on (a tie goes to `expected_width` x `expected_height` when given, else to the
/// first modality in allViperModalities order). Bad lines of a box file are skipped. Every such
/// problem is appended to `problems` as a message that starts with the file's path. Never throws
/// for bad files.
ViperFrame readViperFrame(const ViperSequenceFiles& files, uint64_t frame,
                          const std::map<uint64_t, ViperCameraRow>& camera, const std::set<ViperModality>& wanted,
                          std::vector<std::string>& problems, uint32_t expected_width = 0,
                          uint32_t expected_height = 0);

}  // namespace viper::dataset
