// Statistics of a finished dataset in VIPER's release layout, as VIPER's paper shows them: classes
// per image, instances per image, instances per class, vehicles by distance (and pixels per class),
// per split and condition, and the Jensen-Shannon divergence between the splits' (and the
// conditions') distributions. Read through the layout's own readers (cls, inst, bb files); no ROS.
// Definitions: docs/dataset_generation.md#statistics.
#pragma once

#include "viper/dataset/dataset_plan.h"
#include "viper/ground_truth/class_table.h"

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace viper::dataset {

/// A distribution as counts: bin -> count. Bins are class ids, numbers per image or distance bins.
using Histogram = std::map<int64_t, uint64_t>;

/// The sum of a histogram's counts.
uint64_t histogramTotal(const Histogram& h);

/// The statistics, in the order reports list them.
enum class Statistic {
  kClassesPerImage,     ///< bin: distinct scored classes (class_eval) in an image; count: images
  kInstancesPerImage,   ///< bin: instances of instance classes (instance_eval) in an image; count: images
  kInstancesPerClass,   ///< bin: class id; count: instances, an object counted once per image it is in
  kVehiclesByDistance,  ///< bin: distance_bin_m-wide bin (index); count: visible vehicle boxes
  kPixelsPerClass,      ///< bin: class id; count: pixels
};
const std::vector<Statistic>& allStatistics();
/// File-name stem and title: "classes_per_image", ...
const char* statisticName(Statistic statistic);
std::string statisticTitle(Statistic statistic);  ///< the name with spaces
/// Whether the statistic's bins are class ids.
bool binsAreClasses(Statistic statistic);

/// One sequence to read, with the condition it was generated in ("unknown" without a plan).
struct StatisticsSequence {
  std::string split, seq, condition;
};

struct StatisticsOptions {
  /// Width of the distance bins, metres (> 0).
  double distance_bin_m = 10.0;
  /// The classes counted as vehicles, by name in the class table (names it lacks are ignored).
  /// Default: VIPER's instance-scored vehicles.
  std::vector<std::string> vehicle_classes{"motorcycle", "car", "van", "bus", "truck"};
};

/// Counts of one split in one condition.
struct StatisticsCell {
  uint64_t sequences = 0, images = 0;
  std::map<Statistic, Histogram> histograms;
};

struct DatasetStatistics {
  /// (split, condition) -> counts.
  std::map<std::pair<std::string, std::string>, StatisticsCell> cells;
  std::vector<ClassInfo> classes;  ///< the class table, by id
  std::vector<int> vehicle_class_ids;
  double distance_bin_m = 10.0;
  /// Files that could not be read (or only in part), each message starting with the file's path.
  std::vector<std::string> problems;

  /// The histogram of `statistic` summed over the cells `take` accepts (split, condition).
  Histogram pooled(Statistic statistic,
                   const std::function<bool(const std::string&, const std::string&)>& take) const;
  /// Split names in report order (train, val, test, then others by name); conditions likewise
  /// (day, sunset, rain, snow, night, then others).
  std::vector<std::string> splits() const;
  std::vector<std::string> conditions() const;
};

/// Progress per sequence: its index, the number of sequences, and the sequence.
using StatisticsProgress = std::function<void(size_t, size_t, const StatisticsSequence&)>;

/// Reads every frame of `sequences` under `root` (cls, inst, bb; cls falls back to inst's R channel)
/// and counts. A file that cannot be read is left out and named in `problems`. Throws
/// std::invalid_argument for a distance bin <= 0, std::runtime_error naming the folder when a
/// sequence has no cls, inst or bb file at all.
DatasetStatistics computeDatasetStatistics(const std::string& root, const std::vector<StatisticsSequence>& sequences,
                                           const ClassTable& classes, const StatisticsOptions& options = {},
                                           const StatisticsProgress& progress = {});

/// The sequences of a plan, with their conditions.
std::vector<StatisticsSequence> planSequences(const DatasetPlan& plan);

/// Every sequence of the layout under `root` (every split), condition "unknown". Throws like
/// listViperSplits.
std::vector<StatisticsSequence> layoutSequences(const std::string& root);

/// Jensen-Shannon divergence of the two distributions the histograms' counts make, in bits (log
/// base 2), so within [0, 1]: 0 for the same distribution, 1 for disjoint ones. NaN if either is empty.
double jensenShannonBits(const Histogram& p, const Histogram& q);

}  // namespace viper::dataset
