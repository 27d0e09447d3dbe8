#include "viper/ground_truth/oracle_labels.h"

#include "viper/capture/capture_stream.h"

#include <stdexcept>
#include <string>

namespace viper {

void OracleLabeler::add(const CaptureFrame& frame, const OracleFrame& truth) {
  if (truth.draws.size() != frame.draws.size())
    throw std::invalid_argument("frame " + std::to_string(frame.number) + ": capture has " +
                                std::to_string(frame.draws.size()) + " draws, oracle " +
                                std::to_string(truth.draws.size()) + ": they must be the same draw calls");
  for (size_t i = 0; i < frame.draws.size(); ++i) ++votes_[frame.draws[i].mesh_key][truth.draws[i].class_id];
  ++frames_;
}

LabelTable OracleLabeler::table() const {
  LabelTable table;
  for (const auto& [key, classes] : votes_) {
    int best = 0;
    uint64_t most = 0;
    for (const auto& [c, n] : classes)
      if (n > most) most = n, best = c;
    if (best != 0) table.setMesh(key, static_cast<uint8_t>(best));
  }
  return table;
}

LabelTable labelTableFromOracle(const std::string& capture_path, const std::string& oracle_path, size_t* frames_added) {
  const Oracle oracle = readOracle(oracle_path);
  std::map<uint64_t, const OracleFrame*> by_number;
  for (const auto& f : oracle.frames) by_number[f.number] = &f;
  CaptureReader reader(capture_path);
  CaptureFrame frame;
  OracleLabeler labeler;
  // Only the draw lists are voted on: the images, most of a frame's bytes, are not decompressed.
  while (reader.nextWithoutImages(frame) == CaptureReader::Status::kFrame) {
    const auto it = by_number.find(frame.number);
    if (it != by_number.end()) labeler.add(frame, *it->second);
  }
  if (labeler.framesAdded() == 0)
    throw std::runtime_error("no frame of " + capture_path + " is in the oracle " + oracle_path);
  if (frames_added) *frames_added = labeler.framesAdded();
  return labeler.table();
}

}  // namespace viper
