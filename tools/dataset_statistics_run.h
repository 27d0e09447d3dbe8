// A dataset's statistics computed and written (statistics_report.h), with a line per sequence on
// stderr and every file that could not be read named: shared by `generate --merge` and
// `dataset_statistics`.
#pragma once

#include "viper/dataset/statistics_report.h"

#include <iostream>
#include <string>
#include <vector>

namespace viper_tools {

/// Returns the exit code: 0 written, 1 written with files left out (named), 2 nothing written
/// (the reason on stderr, prefixed with `program`).
inline int writeDatasetStatistics(const std::string& program, const std::string& root,
                                  const std::vector<viper::dataset::StatisticsSequence>& sequences,
                                  const std::string& class_table, const std::string& title,
                                  const viper::dataset::StatisticsOptions& options = {}) {
  try {
    const viper::dataset::DatasetStatistics stats = viper::dataset::computeDatasetStatistics(
        root, sequences, viper::ClassTable::load(class_table), options,
        [&](size_t i, size_t n, const viper::dataset::StatisticsSequence& q) {
          std::cerr << program << ": statistics " << i + 1 << "/" << n << ": " << q.split << "/" << q.seq << " ("
                    << q.condition << ")\n";
        });
    for (size_t i = 0; i < stats.problems.size() && i < 20; ++i)
      std::cerr << program << ": " << stats.problems[i] << "\n";
    if (stats.problems.size() > 20) std::cerr << program << ": ... " << stats.problems.size() - 20 << " more problems\n";
    viper::dataset::writeStatisticsReport(stats, root, title);
    std::cout << program << ": " << root << ": statistics of " << sequences.size()
              << " sequences written: statistics.md, statistics/ (" << stats.problems.size() << " problems)\n";
    return stats.problems.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << program << ": statistics of " << root << ": " << e.what() << "\n";
    return 2;
  }
}

}  // namespace viper_tools
