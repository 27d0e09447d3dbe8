// generate: one sequence of a dataset from a capture (.vcap) or a raw bag, in lockstep and without a
// ROS master: every ground-truth step of replay.launch (the nodes' own code) on every frame, written
// as VIPER's release layout and/or a ground-truth bag, moved into place with a done-marker only when
// complete. Exit code: 0 written (or already finished), 1 written with problems reported (bad
// frames dropped, damaged input: the intact frames written), 2 usage error or an output that cannot
// be written. docs/dataset_generation.md.
#include "viper/dataset/viper_layout.h"
#include "viper/ros/dataset/export_roles.h"
#include "viper/ros/dataset/sequence_generator.h"
#include "viper_progress.h"

#include <ros/package.h>

#include <iostream>
#include <optional>

namespace {

const char* kUsage =
    "usage: generate --input CAPTURE.vcap|RAW.bag --labels LABELS.yaml --out ROOT [options]\n"
    "options: [--split train] [--seq 001] [--outputs layout,bag] [--frames N] [--force]\n"
    "         [--img-format png|jpg] [--jpeg-quality 95] [--png-level 1] [--deflate-level 1]\n"
    "         [--class-table CSV] [--compression none|lz4|bz2] [--no-flow] [--flow-wide-baseline K]\n"
    "         [--extrapolate-frames 10] [--resume-tracks]\n"
    "Writes ROOT/SPLIT/{img,cls,inst,flow,flowbw,bb}/SEQ/, ROOT/SPLIT/camera/SEQ.csv (layout) and\n"
    "ROOT/SPLIT/bag/SEQ.bag (bag: raw and ground-truth topics at their stamps, for bag_player), then\n"
    "ROOT/SPLIT/SEQ.done (frame count and sha256 of every file). A finished sequence (its marker checks\n"
    "out) is skipped unless --force; an unfinished one is redone.\n"
    "Exit code: 0 written or already finished, 1 problems reported (the rest written), 2 error.\n";

struct Options {
  std::string input, labels, class_table;
  bool force = false;
  viper::SequenceSettings sequence;
};

std::string parse(int argc, char** argv, Options& o) {
  viper::SequenceSettings& s = o.sequence;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (arg == "--force") { o.force = true; continue; }
    if (arg == "--no-flow") { s.ground_truth.flow_enabled = false; continue; }
    if (arg == "--resume-tracks") { s.ground_truth.instances.resume_tracks_by_resources = true; continue; }
    if (i + 1 >= argc) return "missing value after " + arg;
    const std::string v = argv[++i];
    try {
      if (arg == "--input") o.input = v;
      else if (arg == "--labels") o.labels = v;
      else if (arg == "--out") s.root = v;
      else if (arg == "--split") s.split = v;
      else if (arg == "--seq") s.seq = v;
      else if (arg == "--frames") s.max_frames = std::stoull(v);
      else if (arg == "--img-format") s.layout.image_extension = v;
      else if (arg == "--jpeg-quality") s.layout.images.jpeg_quality = std::stoi(v);
      else if (arg == "--png-level") s.layout.images.png_compression_level = std::stoi(v);
      else if (arg == "--deflate-level") s.layout.zip.deflate_level = std::stoi(v);
      else if (arg == "--class-table") o.class_table = v;
      else if (arg == "--compression") s.outputs.bag_compression = v;
      else if (arg == "--flow-wide-baseline") s.ground_truth.flow.wide_baseline = std::stoi(v);
      else if (arg == "--extrapolate-frames") s.ground_truth.instances.extrapolate_frames = std::stoi(v);
      else if (arg == "--outputs") {
        s.outputs.layout = v.find("layout") != std::string::npos;
        s.outputs.bag = v.find("bag") != std::string::npos;
        if (!s.outputs.layout && !s.outputs.bag) return "--outputs takes layout, bag or layout,bag";
      } else {
        return "unknown option " + arg;
      }
    } catch (const std::exception&) {
      return "bad number '" + v + "' for " + arg;
    }
  }
  if (o.input.empty() || o.labels.empty() || s.root.empty()) return "--input, --labels and --out are required";
  if (s.outputs.bag_compression != "none" && s.outputs.bag_compression != "lz4" && s.outputs.bag_compression != "bz2")
    return "--compression must be none, lz4 or bz2";
  if (s.ground_truth.flow.wide_baseline < 0) return "--flow-wide-baseline must be >= 0";
  s.ground_truth.flow.window_size = std::max<size_t>(5, s.ground_truth.flow.wide_baseline + 1);
  if (s.ground_truth.instances.extrapolate_frames < 0) return "--extrapolate-frames must be >= 0";
  return viper::exportOptionsProblem(s.layout, "viper", "draws");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  const std::string error = parse(argc, argv, o);
  if (!error.empty()) {
    std::cerr << "generate: " << error << "\n" << kUsage;
    return 2;
  }
  std::string class_table = o.class_table;
  if (class_table.empty()) {
    const std::string share = ros::package::getPath("viper");
    class_table = (share.empty() ? std::string(VIPER_SOURCE_DIR) : share) + "/config/viper_classes.csv";
  }
  std::optional<viper::SequenceGenerator> generator;
  std::unique_ptr<viper::RawFrames> input;
  try {
    viper::ClassTable classes = viper::ClassTable::load(class_table);
    o.sequence.layout.palette = viper::classPalette(class_table);
    viper::dataset::viperFramePath(o.sequence.root, o.sequence.split, "img", o.sequence.seq, 0, "png");  // checks names
    generator.emplace(o.sequence, viper::LabelTable::load(o.labels), std::move(classes));
    std::string why;
    if (!o.force && generator->finished(&why)) {
      std::cout << "generate: " << o.sequence.split << "/" << o.sequence.seq << " is finished ("
                << generator->markerPath().string() << " checks out); --force redoes it\n";
      return 0;
    }
    input = viper::openRawFrames(o.input);
  } catch (const std::exception& e) {
    std::cerr << "generate: " << e.what() << "\n";
    return 2;
  }
  viper_tools::ProgressBar bar("generate " + o.sequence.split + "/" + o.sequence.seq, input->frameCount(), "frames");
  viper::SequenceResult result;
  try {
    // finished() was checked above: run() need not check it again.
    result = generator->run(*input, /*force=*/true, [&](uint64_t done, uint64_t) { bar.update(done); });
  } catch (const std::exception& e) {
    bar.interrupt();
    std::cerr << "generate: " << e.what() << "\n";
    return 2;
  }
  bar.interrupt();
  // Each at most 20 times: a long sequence may say the same thing of every frame.
  auto print = [](const std::vector<std::string>& lines, const char* what) {
    for (size_t i = 0; i < lines.size() && i < 20; ++i) std::cerr << "generate: " << lines[i] << "\n";
    if (lines.size() > 20) std::cerr << "generate: ... " << lines.size() - 20 << " more " << what << "\n";
  };
  print(result.warnings, "warnings");
  print(result.problems, "problems");
  std::cout << "generate: " << o.sequence.split << "/" << o.sequence.seq << ": " << result.frames << " frames ("
            << result.dropped << " dropped, " << result.problems.size() << " problems, " << result.warnings.size()
            << " warnings) from " << o.input << " into " << o.sequence.root << "; marker "
            << result.marker.string() << "\n";
  return result.problems.empty() ? 0 : 1;
}
