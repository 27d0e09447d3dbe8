// dataset_statistics: the statistics of a dataset in VIPER's release layout (classes and instances
// per image, instances per class, vehicles by distance, pixels per class; per split and condition;
// Jensen-Shannon divergences) as ROOT/statistics.md and ROOT/statistics/*.csv, *.png. What
// `generate --merge` writes after the manifest, computed again. docs/dataset_generation.md#statistics.
#include "dataset_statistics_run.h"

#include <ros/package.h>

#include <filesystem>

namespace {

const char* kUsage =
    "usage: dataset_statistics --root ROOT [--plan PLAN.yaml] [--class-table CSV] [--distance-bin-m 10]\n"
    "Reads every sequence of the plan (without --plan: every sequence under ROOT, condition 'unknown')\n"
    "and writes ROOT/statistics.md and ROOT/statistics/. Exit code: 0 written, 1 written with files\n"
    "that could not be read (named), 2 error.\n";

}  // namespace

int main(int argc, char** argv) {
  std::string root, plan, class_table;
  viper::dataset::StatisticsOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    }
    if (i + 1 >= argc) {
      std::cerr << "dataset_statistics: missing value after " << arg << "\n" << kUsage;
      return 2;
    }
    const std::string v = argv[++i];
    if (arg == "--root") root = v;
    else if (arg == "--plan") plan = v;
    else if (arg == "--class-table") class_table = v;
    else if (arg == "--distance-bin-m") {
      size_t used = 0;
      try {
        options.distance_bin_m = std::stod(v, &used);
      } catch (const std::exception&) {
      }
      if (used != v.size() || !(options.distance_bin_m > 0.0)) {
        std::cerr << "dataset_statistics: --distance-bin-m takes metres > 0, not '" << v << "'\n";
        return 2;
      }
    } else {
      std::cerr << "dataset_statistics: unknown option " << arg << "\n" << kUsage;
      return 2;
    }
  }
  if (root.empty()) {
    std::cerr << "dataset_statistics: --root is required\n" << kUsage;
    return 2;
  }
  if (class_table.empty()) {
    const std::string share = ros::package::getPath("viper");
    class_table = (share.empty() ? std::string(VIPER_SOURCE_DIR) : share) + "/config/viper_classes.csv";
  }
  std::vector<viper::dataset::StatisticsSequence> sequences;
  std::filesystem::path name = std::filesystem::path(root).lexically_normal();
  if (name.filename().empty()) name = name.parent_path();  // "ROOT/"
  std::string title = name.filename().string();
  try {
    if (plan.empty()) {
      sequences = viper::dataset::layoutSequences(root);
    } else {
      const viper::dataset::DatasetPlan p = viper::dataset::readPlan(plan);
      sequences = viper::dataset::planSequences(p);
      title = p.name;
    }
  } catch (const std::exception& e) {
    std::cerr << "dataset_statistics: " << e.what() << "\n";
    return 2;
  }
  return viper_tools::writeDatasetStatistics("dataset_statistics", root, sequences, class_table, title, options);
}
