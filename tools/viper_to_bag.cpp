// viper_to_bag: converts a folder in VIPER's release layout into a bag with the player's topics and
// stamps (the package's BagWriter), with a progress bar on stderr. Bad files are reported (naming
// the file) and left out; the rest is converted. Exit code: 0 = everything converted, 1 = problems
// reported, the rest converted, 2 = usage error, missing root/split/sequence, or the bag cannot be
// written.
// docs/viper_layout.md has the details.
#include "command_line.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ros/dataset/viper_bag_conversion.h"
#include "viper_progress.h"

#include <ros/package.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace {

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Writes DIR/SPLIT/<modality>/<seq>/... as the topics the player publishes (/capture/color/image_raw,\n"
      "/ground_truth/semantic, /ground_truth/instance_ids, /ground_truth/instances_viper,\n"
      "/ground_truth/flow/forward, /ground_truth/flow/backward, /ground_truth/odom, /ground_truth/boxes,\n"
      "/ground_truth/boxes_optical, /capture/color/camera_info, /tf, /tf_static); frame n of a sequence\n"
      "is stamped n / fps after its first frame.",
      "viper_to_bag");
  viper::ViperToBagOptions o;
  std::string out, class_table, sequences, modalities;
  double start_time = 0.0;
  app.add_option("--root", o.root, "the layout's root")->required()->type_name("DIR");
  app.add_option("--out", out, "the bag to write")->required()->type_name("OUT.bag");
  app.add_option("--split", o.split, "the split (default: the root's only split, or train)")->type_name("SPLIT");
  app.add_option("--sequence", sequences, "the sequences (default: every sequence of the split)")
      ->type_name("001,002");
  app.add_option("--modalities", modalities, "what to convert (default: every modality)")
      ->type_name("img,cls,inst,flow,flowbw,bb,camera");
  app.add_option("--fps", o.fps, "frames a second (> 0)")->capture_default_str();
  const CLI::Option* start_time_given =
      app.add_option("--start-time", start_time, "stamp of the first frame, s (> 0; default: as the player's)")
          ->type_name("T");
  app.add_option("--compression", o.compression, "the bag's chunks")
      ->type_name("none|lz4|bz2")
      ->capture_default_str();
  app.add_flag("--semantic-color", o.semantic_color, "also /ground_truth/semantic_color (the class table's colors)");
  app.add_option("--class-table", class_table,
                 "the classes: names of boxes, colors (default: the package's config/viper_classes.csv)")
      ->type_name("CSV");
  app.add_option("--map-frame", o.frames.map, "tf's map frame")->type_name("FRAME")->capture_default_str();
  app.add_option("--body-frame", o.frames.body, "tf's camera body frame")->type_name("FRAME")->capture_default_str();
  app.add_option("--frame-id", o.frames.optical, "the images' optical frame")
      ->type_name("FRAME")
      ->capture_default_str();
  app.add_option("--prefetch", o.prefetch, "frames read ahead by a second thread, 0..16 (0: read in line)")
      ->capture_default_str();
  app.footer("Exit status: 0 all converted; 1 problems reported (the rest converted); 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  std::string error;
  if (app.count("--sequence")) o.sequences = splitList(sequences);
  if (app.count("--modalities")) {
    o.modalities.clear();
    o.camera = false;
    for (const std::string& m : splitList(modalities)) {
      if (m == "camera") o.camera = true;
      else if (auto modality = viper::dataset::viperModalityFromName(m)) o.modalities.insert(*modality);
      else if (error.empty()) error = "unknown modality '" + m + "' (img, cls, inst, flow, flowbw, bb, camera)";
    }
  }
  if (*start_time_given) o.start_time = start_time;
  if (error.empty() && !(o.fps > 0)) error = "--fps must be > 0";
  if (error.empty() && o.start_time && !(*o.start_time > 0)) error = "--start-time must be > 0";
  if (error.empty() && o.compression != "none" && o.compression != "lz4" && o.compression != "bz2")
    error = "--compression must be none, lz4 or bz2";
  if (error.empty() && (o.prefetch < 0 || o.prefetch > 16)) error = "--prefetch must be 0..16";
  if (!error.empty()) return viper_tools::usageError(app, error);
  if (class_table.empty()) {
    const std::string share = ros::package::getPath("viper");
    class_table = (share.empty() ? std::string(VIPER_SOURCE_DIR) : share) + "/config/viper_classes.csv";
  }
  viper::ClassTable classes;
  try {
    classes = viper::ClassTable::load(class_table);
  } catch (const std::exception& e) {
    std::cerr << "viper_to_bag: " << e.what() << " (--class-table)\n";
    return 2;
  }
  o.classes = &classes;

  std::unique_ptr<viper_tools::ProgressBar> bar;
  const auto start = std::chrono::steady_clock::now();
  try {
    const viper::ViperToBagStats stats = viper::convertViperToBag(
        o, out,
        [&](const std::string& p) {
          if (bar) bar->interrupt();
          std::cerr << "viper_to_bag: " << p << "\n";
        },
        [&](size_t done, size_t total) {
          if (!bar) bar = std::make_unique<viper_tools::ProgressBar>("viper_to_bag", total, "frames");
          bar->update(done);
        });
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "viper_to_bag: wrote " << stats.frames << " frames of " << stats.sequences << " sequence(s), "
              << stats.messages << " messages (" << stats.message_bytes / 1e6 << " MB) to " << out << " in " << s
              << " s (" << stats.frames / s << " frames/s); " << stats.problems << " problems\n";
    return stats.problems == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    if (bar) bar->interrupt();
    std::cerr << "viper_to_bag: " << e.what() << "\n";
    return 2;
  }
}
