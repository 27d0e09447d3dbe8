// Builds a resource label table from captures and a program's oracle: the stand-in for VIPER's
// once-per-asset human annotation. Tools and tests only; ground-truth nodes read just the table.
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/label_table.h"
#include "viper/ground_truth/oracle.h"

#include <map>
#include <string>

namespace viper {

/// Collects, per mesh key, the true classes of the draws that used it.
class OracleLabeler {
 public:
  /// Adds one captured frame and the oracle's frame of the same number. Throws
  /// std::invalid_argument if their draw counts differ (they must be the same draw calls).
  void add(const CaptureFrame& frame, const OracleFrame& truth);
  /// Each mesh key labelled with the class most of its draws had (class 0 gives no label), as an
  /// annotator labels a shared wheel once.
  LabelTable table() const;
  size_t framesAdded() const { return frames_; }

 private:
  std::map<uint64_t, std::map<int, uint64_t>> votes_;
  size_t frames_ = 0;
};

/// The label table of one capture of a program and the program's oracle of the same run: every
/// frame of the capture that the oracle has is added. Throws std::runtime_error naming the file
/// when either cannot be read or no frame of the capture is in the oracle.
LabelTable labelTableFromOracle(const std::string& capture_path, const std::string& oracle_path,
                                size_t* frames_added = nullptr);

}  // namespace viper
