// The report of a dataset's statistics (dataset_statistics.h): one CSV per statistic in long format
// (`split,condition,bin,count`), the Jensen-Shannon divergences (`divergence.csv`), one PNG per
// statistic (by split and by condition, OpenCV drawing through viper_report) under
// ROOT/statistics/, and ROOT/statistics.md beside the manifest. docs/dataset_generation.md#statistics.
#pragma once

#include "viper/dataset/dataset_statistics.h"

#include <string>
#include <vector>

namespace viper::dataset {

/// A bin as reports name it: the class name for class statistics (the id where the table has no such
/// class), the distance bin's lower edge in metres for vehicles ("0", "10", ...), else the number.
std::string binLabel(const DatasetStatistics& s, Statistic statistic, int64_t bin);

/// `split,condition,bin,count`: a row per split, condition and bin with a count, splits and
/// conditions in report order, bins ascending.
std::string statisticCsv(const DatasetStatistics& s, Statistic statistic);

/// One divergence: between two splits (over every condition) or two conditions (over every split).
struct Divergence {
  Statistic statistic;
  std::string between;  ///< "split" or "condition"
  std::string a, b;
  double bits = 0.0;    ///< jensenShannonBits; NaN where one side has no count
};

/// Every pair of splits and every pair of conditions, for every statistic.
std::vector<Divergence> divergences(const DatasetStatistics& s);

/// `statistic,between,a,b,jsd_bits` (empty where undefined).
std::string divergenceCsv(const std::vector<Divergence>& d);

/// statistics.md: images and means per split and condition, the divergences, and per statistic its
/// figure (`statistics/<name>.png`, relative) and its counts by split, by condition and over all.
std::string statisticsMarkdown(const DatasetStatistics& s, const std::string& title);

/// Draws a statistic as `path` (PNG): its distribution (share of the counts per bin) by split
/// beside the same by condition. Throws std::runtime_error naming the file if it cannot be written.
void writeStatisticPlot(const DatasetStatistics& s, Statistic statistic, const std::string& path);

/// Writes ROOT/statistics/{<statistic>.csv, <statistic>.png, divergence.csv} and ROOT/statistics.md;
/// returns the paths written. Throws std::runtime_error naming the file that could not be written.
std::vector<std::string> writeStatisticsReport(const DatasetStatistics& s, const std::string& root,
                                               const std::string& title);

}  // namespace viper::dataset
