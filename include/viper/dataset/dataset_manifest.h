// The merge step of a dataset plan: every planned sequence must be finished (its done-marker there
// and every file with its checksum); then the dataset's manifest is written: MANIFEST.sha256 (every
// file of every sequence, sha256sum's format, `sha256sum -c` reads it from the root) and
// manifest.md (sequences and frames per split and condition). Refuses, naming what is missing,
// otherwise (docs/dataset_generation.md).
#pragma once

#include "viper/dataset/dataset_plan.h"

#include <string>
#include <vector>

namespace viper::dataset {

/// What merging found: `missing` names each planned sequence that is not finished and why; the
/// manifest is written only when it is empty.
struct MergeResult {
  std::vector<std::string> missing;
  uint64_t sequences = 0, frames = 0, files = 0;
};

/// Checks every sequence of `plan` under `root` and, if all are finished, writes the manifest.
/// Throws std::runtime_error naming the file if the manifest cannot be written.
MergeResult mergeDataset(const DatasetPlan& plan, const std::string& root);

}  // namespace viper::dataset
