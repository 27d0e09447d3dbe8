// viper_to_bag: converts a folder in VIPER's release layout into a bag with the player's topics and
// stamps (rosbag C++ API), with a progress bar on stderr. Bad files are reported (naming the file)
// and left out; the rest is converted. Exit code: 0 = everything converted, 1 = problems reported,
// the rest converted, 2 = usage error, missing root/split/sequence, or the bag cannot be written.
// docs/viper_layout.md has the details.
#include "viper/ground_truth/class_table.h"
#include "viper/ros/dataset/viper_bag_conversion.h"
#include "viper_progress.h"

#include <ros/package.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace {

const char* kUsage =
    "usage: viper_to_bag --root DIR --out OUT.bag [--split train] [--sequence 001,002]\n"
    "                    [--modalities img,cls,inst,flow,flowbw,bb,camera] [--fps 15] [--start-time T]\n"
    "                    [--compression none|lz4|bz2] [--semantic-color] [--class-table CSV]\n"
    "                    [--map-frame map] [--body-frame camera] [--frame-id camera_optical] [--prefetch 2]\n"
    "Writes DIR/SPLIT/<modality>/<seq>/... as the topics the player publishes (/capture/color/image_raw,\n"
    "/ground_truth/semantic, /ground_truth/instance_ids, /ground_truth/instances_viper,\n"
    "/ground_truth/flow/forward, /ground_truth/flow/backward, /ground_truth/odom, /ground_truth/boxes,\n"
    "/ground_truth/boxes_optical, /capture/color/camera_info, /tf, /tf_static); frame n of a sequence\n"
    "is stamped n / fps after its first frame. Defaults: the root's only split (or train), every\n"
    "sequence, every modality.\n"
    "Exit code: 0 all converted, 1 problems reported (the rest converted), 2 error.\n";

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
  viper::ViperToBagOptions o;
  std::string out, class_table, error;
  for (int i = 1; i < argc && error.empty(); ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    }
    if (arg == "--semantic-color") {
      o.semantic_color = true;
      continue;
    }
    if (i + 1 >= argc) {
      error = "missing value after " + arg;
      break;
    }
    const std::string v = argv[++i];
    try {
      if (arg == "--root") o.root = v;
      else if (arg == "--out") out = v;
      else if (arg == "--split") o.split = v;
      else if (arg == "--sequence") o.sequences = splitList(v);
      else if (arg == "--modalities") {
        o.modalities.clear();
        o.camera = false;
        for (const std::string& m : splitList(v)) {
          if (m == "camera") o.camera = true;
          else if (auto modality = viper::dataset::viperModalityFromName(m)) o.modalities.insert(*modality);
          else error = "unknown modality '" + m + "' (img, cls, inst, flow, flowbw, bb, camera)";
        }
      } else if (arg == "--fps") o.fps = std::stod(v);
      else if (arg == "--start-time") o.start_time = std::stod(v);
      else if (arg == "--compression") o.compression = v;
      else if (arg == "--class-table") class_table = v;
      else if (arg == "--map-frame") o.frames.map = v;
      else if (arg == "--body-frame") o.frames.body = v;
      else if (arg == "--frame-id") o.frames.optical = v;
      else if (arg == "--prefetch") o.prefetch = std::stoi(v);
      else error = "unknown option " + arg;
    } catch (const std::exception&) {
      error = "bad number '" + v + "' for " + arg;
    }
  }
  if (error.empty() && (o.root.empty() || out.empty())) error = "--root and --out are required";
  if (error.empty() && !(o.fps > 0)) error = "--fps must be > 0";
  if (error.empty() && o.start_time && !(*o.start_time > 0)) error = "--start-time must be > 0";
  if (error.empty() && o.compression != "none" && o.compression != "lz4" && o.compression != "bz2")
    error = "--compression must be none, lz4 or bz2";
  if (error.empty() && (o.prefetch < 0 || o.prefetch > 16)) error = "--prefetch must be 0..16";
  if (!error.empty()) {
    std::cerr << "viper_to_bag: " << error << "\n" << kUsage;
    return 2;
  }
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
