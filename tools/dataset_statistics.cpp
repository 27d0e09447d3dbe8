// dataset_statistics: the statistics of a dataset in VIPER's release layout (classes and instances
// per image, instances per class, vehicles by distance, pixels per class; per split and condition;
// Jensen-Shannon divergences) as ROOT/statistics.md and ROOT/statistics/*.csv, *.png. What
// `generate --merge` writes after the manifest, computed again. docs/dataset_generation.md#statistics.
#include "command_line.h"
#include "dataset_statistics_run.h"

#include <ros/package.h>

#include <cstdlib>
#include <filesystem>

int main(int argc, char** argv) {
  CLI::App app(
      "Reads every sequence of the plan (without --plan: every sequence under ROOT, condition 'unknown')\n"
      "and writes ROOT/statistics.md and ROOT/statistics/.",
      "dataset_statistics");
  std::string root, plan, class_table;
  viper::dataset::StatisticsOptions options;
  app.add_option("--root", root, "the dataset, in VIPER's release layout")->required()->type_name("ROOT");
  app.add_option("--plan", plan, "its plan: the sequences, their conditions and the dataset's name")
      ->type_name("PLAN.yaml");
  app.add_option("--class-table", class_table, "the classes (default: the package's config/viper_classes.csv)")
      ->type_name("CSV");
  app.add_option("--distance-bin-m", options.distance_bin_m, "width of the bins of vehicles by distance, metres")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& v) {
            return std::strtod(v.c_str(), nullptr) > 0.0 ? "" : "takes metres > 0, not '" + v + "'";
          },
          ""));
  app.footer("Exit status: 0 written; 1 written with files that could not be read (named); 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
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
