// generate: one sequence of a dataset from a capture (.vcap) or a raw bag, in lockstep and without a
// ROS master: every ground-truth step of replay.launch (the nodes' own code) on every frame, written
// as VIPER's release layout and/or a ground-truth bag, moved into place with a done-marker only when
// complete. Exit code: 0 written (or already finished), 1 written with problems reported (bad
// frames dropped, damaged input: the intact frames written), 2 usage error or an output that cannot
// be written. docs/dataset_generation.md.
#include "command_line.h"
#include "viper/dataset/dataset_manifest.h"
#include "viper/dataset/dataset_plan.h"
#include "viper/dataset/sequence_lock.h"
#include "viper/dataset/viper_layout.h"
#include "viper/ground_truth/oracle_labels.h"
#include "viper/ros/dataset/export_roles.h"
#include "viper/ros/dataset/sequence_generator.h"
#include "dataset_statistics_run.h"
#include "viper_progress.h"

#include <ros/package.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace {

struct Options {
  std::string input, labels, class_table;
  std::string modalities;    // --modalities
  int cloud_decimation = 1;  // --cloud-decimation
  std::string plan, write_plan;
  uint32_t task_index = 0, task_count = 0;
  bool task_index_given = false, task_count_given = false;  // both or neither (shard())
  bool force = false, merge = false;
  viper::SequenceSettings sequence;
};

// The command line's options, into `o` (what only the whole line tells: check()).
void addOptions(CLI::App& app, Options& o, int& writer_threads, std::string& outputs) {
  viper::SequenceSettings& s = o.sequence;
  app.add_option("--input", o.input, "one sequence from a capture or a raw bag")->type_name("CAPTURE.vcap|RAW.bag");
  app.add_option("--labels", o.labels,
                 "the label table (with --plan: instead of the labels from the world's own oracle of the run)")
      ->type_name("LABELS.yaml");
  app.add_option("--out", s.root, "the dataset's root")->type_name("ROOT");
  app.add_option("--plan", o.plan,
                 "every sequence of the plan (or shard I of N: every N-th from the I-th; SLURM_ARRAY_TASK_ID and "
                 "SLURM_ARRAY_TASK_COUNT when set), each the built-in world under capture with the sequence's "
                 "condition, ego mode, seed, length and size (and the plan's city and the sequence's region); "
                 "with --write-plan, --merge: the plan to write, to merge")
      ->type_name("PLAN.yaml");
  app.add_option("--task-index", o.task_index, "with --plan, the shard I (with --task-count)");
  app.add_option("--task-count", o.task_count, "with --plan, the number of shards N (with --task-index)");
  app.add_option("--write-plan", o.write_plan, "writes the preset plan to --plan")->type_name("viper|small|tiny");
  app.add_flag("--merge", o.merge,
               "checks every planned sequence is finished, then writes ROOT/MANIFEST.sha256 and ROOT/manifest.md "
               "(refuses, naming what is missing, otherwise: exit 2), then the dataset's statistics: "
               "ROOT/statistics.md and ROOT/statistics/ (dataset_statistics computes them again)");
  app.add_option("--split", s.split, "the split")->type_name("SPLIT")->capture_default_str();
  app.add_option("--seq", s.seq, "the sequence (with --input)")->type_name("SEQ")->capture_default_str();
  app.add_option("--outputs", outputs,
                 "what to write, comma-separated: VIPER's layout, the ground-truth bag, and the training formats "
                 "Cityscapes (gtFine), COCO (instances, visible and amodal), KITTI (flow, depth) under "
                 "SPLIT/training/SEQ (docs/training_formats.md)")
      ->type_name("layout,bag,cityscapes,coco,kitti")
      ->capture_default_str();
  app.add_option("--modalities", o.modalities,
                 "ground truth beyond VIPER's into the bag, comma-separated, as their nodes publish it: "
                 "normals (/ground_truth/normals), labelled_cloud (/ground_truth/labelled_cloud), scene_flow "
                 "(/ground_truth/flow/scene_flow), amodal (/ground_truth/amodal/objects), or all")
      ->type_name("normals,labelled_cloud,scene_flow,amodal|all");
  app.add_option("--cloud-decimation", o.cloud_decimation, "labelled_cloud: every K-th pixel in both directions (>= 1)")
      ->capture_default_str();
  app.add_option("--frames", s.max_frames, "only the first N frames (0: all)");
  app.add_flag("--force", o.force, "redo a finished sequence");
  app.add_option("--img-format", s.layout.image_extension, "img files")->type_name("png|jpg")->capture_default_str();
  app.add_option("--jpeg-quality", s.layout.images.jpeg_quality, "0..100")->capture_default_str();
  app.add_option("--png-level", s.layout.images.png_compression_level, "PNG compression, 0..9")
      ->capture_default_str();
  app.add_option("--deflate-level", s.layout.zip.deflate_level, "npz compression, 0..9")->capture_default_str();
  app.add_option("--class-table", o.class_table, "the classes (default: the package's config/viper_classes.csv)")
      ->type_name("CSV");
  app.add_option("--compression", s.outputs.bag_compression, "the bag's chunks")
      ->type_name("none|lz4|bz2")
      ->capture_default_str();
  app.add_flag_callback("--no-flow", [&s] { s.ground_truth.flow_enabled = false; }, "no flow, no flowbw");
  app.add_option("--flow-wide-baseline", s.ground_truth.flow.wide_baseline,
                 "K >= 0: also the flow of frame f to f+K (0: none)")
      ->capture_default_str();
  app.add_option("--extrapolate-frames", s.ground_truth.instances.extrapolate_frames,
                 "frames a track is kept without its object (>= 0)")
      ->capture_default_str();
  app.add_flag("--resume-tracks", s.ground_truth.instances.resume_tracks_by_resources,
               "an object back after a long gap takes up its own track id (the tracker's resume_by_resources)");
  app.add_option("--writer-threads", writer_threads,
                 "threads that encode the layout's PNG and npz files beside the ground truth, 0..64 (default: one "
                 "per CPU this process may use, at most 4; 0: none). The files are the same either way");
}

// What only the whole command line tells; returns the error, empty if none.
std::string check(Options& o, const CLI::App& app, int writer_threads, const std::string& outputs) {
  viper::SequenceSettings& s = o.sequence;
  o.task_index_given = app.count("--task-index") > 0;
  o.task_count_given = app.count("--task-count") > 0;
  if (app.count("--writer-threads")) {
    if (writer_threads < 0 || writer_threads > 64)
      return "--writer-threads must be 0..64, got " + std::to_string(writer_threads);
    s.layout.writer_threads = static_cast<unsigned>(writer_threads);
  }
  if (app.count("--outputs")) {
    s.outputs.layout = s.outputs.bag = false;
    std::istringstream list(outputs);
    for (std::string name; std::getline(list, name, ',');) {
      bool* flag = name == "layout"       ? &s.outputs.layout
                   : name == "bag"        ? &s.outputs.bag
                   : name == "cityscapes" ? &s.outputs.cityscapes
                   : name == "coco"       ? &s.outputs.coco
                   : name == "kitti"      ? &s.outputs.kitti
                                          : nullptr;
      if (!flag) return "--outputs takes a comma-separated list of layout, bag, cityscapes, coco, kitti; got '" + name + "'";
      *flag = true;
    }
  }
  if (!o.modalities.empty()) {
    std::istringstream list(o.modalities == "all" ? "normals,labelled_cloud,scene_flow,amodal" : o.modalities);
    for (std::string name; std::getline(list, name, ',');) {
      if (name == "normals") s.ground_truth.normals = true;
      else if (name == "labelled_cloud") s.ground_truth.cloud_decimation = o.cloud_decimation;
      else if (name == "scene_flow") s.ground_truth.scene_flow = true;
      else if (name == "amodal") s.ground_truth.amodal = true;
      else return "--modalities takes normals, labelled_cloud, scene_flow, amodal (comma-separated) or all; got '" + name + "'";
    }
    if (!s.outputs.bag) return "--modalities are written into the ground-truth bag: --outputs must have bag";
    if (s.ground_truth.scene_flow && !s.ground_truth.flow_enabled) return "--modalities scene_flow needs the flow (not --no-flow)";
  }
  if (o.cloud_decimation < 1) return "--cloud-decimation must be >= 1";
  if (!o.write_plan.empty()) return o.plan.empty() ? "--write-plan needs --plan (the file to write)" : "";
  if (o.merge && (o.plan.empty() || s.root.empty())) return "--merge needs --plan and --out";
  if (!o.plan.empty()) {
    if (!o.input.empty()) return "give --input or --plan, not both";
    if (s.root.empty()) return "--out is required";
  } else if (o.input.empty() || o.labels.empty() || s.root.empty()) {
    return "--input, --labels and --out are required";
  }
  if (s.outputs.bag_compression != "none" && s.outputs.bag_compression != "lz4" && s.outputs.bag_compression != "bz2")
    return "--compression must be none, lz4 or bz2";
  if (s.ground_truth.flow.wide_baseline < 0) return "--flow-wide-baseline must be >= 0";
  s.ground_truth.flow.window_size = std::max<size_t>(5, s.ground_truth.flow.wide_baseline + 1);
  if (s.ground_truth.instances.extrapolate_frames < 0) return "--extrapolate-frames must be >= 0";
  return viper::exportOptionsProblem(s.layout, "viper", "draws");
}

// The wall time and the CPU time of the children waited for (a program under capture) from its
// construction to addTo().
class ChildClock {
 public:
  ChildClock() : wall0_(std::chrono::steady_clock::now()), cpu0_(childrenCpu()) {}
  void addTo(viper::StageTimes& times, const std::string& stage) const {
    times.add(stage, childrenCpu() - cpu0_,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count());
  }

 private:
  static double childrenCpu() {
    rusage u{};
    getrusage(RUSAGE_CHILDREN, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  }
  std::chrono::steady_clock::time_point wall0_;
  double cpu0_;
};

}  // namespace

// One sequence from the frames `open()` gives; returns the exit code.
// `labels()` is asked after `open()`: a planned sequence's labels come from its own run.
// One generator per sequence at a time (an array resubmitted while a task of the first still runs):
// held from the finished-check to the last temporary file removed. nullptr (after a message) if the
// lock file cannot be made; the caller then reports the sequence failed.
std::unique_ptr<viper::dataset::SequenceLock> lockSequence(const std::string& root, const std::string& split,
                                                           const std::string& seq) {
  try {
    return std::make_unique<viper::dataset::SequenceLock>(
        viper::dataset::sequenceLockPath(root, split, seq), [&](const std::string& holder) {
          std::cout << "generate: " << split << "/" << seq << " is being generated by another process ("
                    << holder.substr(0, holder.find('\n')) << "): waiting for it\n" << std::flush;
        });
  } catch (const std::exception& e) {
    std::cerr << "generate: " << split << "/" << seq << ": " << e.what() << "\n";
    return nullptr;
  }
}

int oneSequence(const Options& o, const viper::SequenceSettings& settings, const std::string& class_table,
                const std::function<viper::LabelTable()>& labels, const std::string& source,
                const std::function<std::unique_ptr<viper::RawFrames>()>& open,
                const viper::StageTimes& before = viper::StageTimes()) {
  const std::string name = settings.split + "/" + settings.seq;
  std::optional<viper::SequenceGenerator> generator;
  std::unique_ptr<viper::RawFrames> input;
  try {
    viper::ClassTable classes = viper::ClassTable::load(class_table);
    viper::SequenceSettings s = settings;
    s.layout.palette = viper::classPalette(class_table);
    viper::dataset::viperFramePath(s.root, s.split, "img", s.seq, 0, "png");  // checks the names
    generator.emplace(s, viper::LabelTable(), classes);
    if (!o.force && generator->finished()) {
      std::cout << "generate: " << name << " is finished (" << generator->markerPath().string()
                << " checks out); --force redoes it\n";
      return 0;
    }
    input = open();
    generator.emplace(s, labels(), std::move(classes));
  } catch (const std::exception& e) {
    std::cerr << "generate: " << name << ": " << e.what() << "\n";
    return 2;
  }
  viper_tools::ProgressBar bar("generate " + name, input->frameCount(), "frames");
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
  std::cout << "generate: " << name << ": " << result.frames << " frames (" << result.dropped << " dropped, "
            << result.problems.size() << " problems, " << result.warnings.size() << " warnings) from " << source
            << " into " << settings.root << "; marker " << result.marker.string();
  if (!result.skipped)
    std::cout << " (checksums: " << result.checksums_read_back << " of " << result.files << " files read back)";
  std::cout << "\n";
  if (!result.skipped) {
    // What came before the frames (the program under capture, its labels) heads the table.
    viper::StageTimes all = before;
    for (const viper::StageTimes::Stage& st : result.stages.stages()) all.add(st.name, st.cpu_s, st.wall_s);
    std::cout << "generate: " << name << ": where the time went\n" << all.table(result.frames);
  }
  return result.problems.empty() ? 0 : 1;
}

// The shard to generate: --task-index/--task-count, else Slurm's array variables, else everything.
bool shard(const Options& o, uint32_t& index, uint32_t& count, std::string& error) {
  index = 0, count = 1;
  const char* slurm_id = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* slurm_count = std::getenv("SLURM_ARRAY_TASK_COUNT");
  if (o.task_index_given || o.task_count_given) {
    if (!o.task_index_given || !o.task_count_given)
      return error = "--task-index and --task-count go together", false;
    index = o.task_index, count = o.task_count;
  } else if (slurm_id && slurm_count) {
    index = static_cast<uint32_t>(std::stoul(slurm_id)), count = static_cast<uint32_t>(std::stoul(slurm_count));
    const char* slurm_min = std::getenv("SLURM_ARRAY_TASK_MIN");
    if (slurm_min) index -= static_cast<uint32_t>(std::stoul(slurm_min));  // arrays may start at 1
  }
  if (count == 0 || index >= count)
    return error = "task " + std::to_string(index) + " of " + std::to_string(count) + " does not exist", false;
  return true;
}

int main(int argc, char** argv) {
  CLI::App app(
      "generate --input CAPTURE.vcap|RAW.bag --labels LABELS.yaml --out ROOT [options]\n"
      "generate --plan PLAN.yaml --out ROOT [--task-index I --task-count N] [options]\n"
      "generate --write-plan viper|small|tiny --plan PLAN.yaml\n"
      "generate --merge --plan PLAN.yaml --out ROOT\n"
      "Writes ROOT/SPLIT/{img,cls,inst,flow,flowbw,bb}/SEQ/, ROOT/SPLIT/camera/SEQ.csv (layout) and\n"
      "ROOT/SPLIT/bag/SEQ.bag (bag: raw and ground-truth topics at their stamps, for bag_player), then\n"
      "ROOT/SPLIT/SEQ.done (frame count and sha256 of every file). A finished sequence (its marker checks\n"
      "out) is skipped unless --force; an unfinished one is redone.",
      "generate");
  Options o;
  o.sequence.layout.writer_threads = viper::dataset::WriteQueue::defaultThreads();
  int writer_threads = 0;
  std::string outputs = "layout,bag";
  addOptions(app, o, writer_threads, outputs);
  app.footer("Exit status: 0 written or already finished; 1 problems reported (the rest written); 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  if (const std::string error = check(o, app, writer_threads, outputs); !error.empty())
    return viper_tools::usageError(app, error);
  if (!o.write_plan.empty()) {
    try {
      const viper::dataset::DatasetPlan plan = viper::dataset::presetPlan(o.write_plan);
      viper::dataset::writePlan(o.plan, plan);
      std::cout << "generate: wrote " << o.plan << ": " << plan.sequences.size() << " sequences, "
                << plan.totalFrames() << " frames\n";
      return 0;
    } catch (const std::exception& e) {
      std::cerr << "generate: " << e.what() << "\n";
      return 2;
    }
  }
  const std::string share = ros::package::getPath("viper");
  const std::string package = share.empty() ? std::string(VIPER_SOURCE_DIR) : share;
  const std::string class_table = o.class_table.empty() ? package + "/config/viper_classes.csv" : o.class_table;
  if (o.plan.empty()) {
    const auto lock = lockSequence(o.sequence.root, o.sequence.split, o.sequence.seq);
    if (!lock) return 2;
    return oneSequence(o, o.sequence, class_table, [&] { return viper::LabelTable::load(o.labels); }, o.input,
                       [&] { return viper::openRawFrames(o.input); });
  }

  viper::dataset::DatasetPlan plan;
  uint32_t index = 0, count = 1;
  std::string shard_error;
  try {
    plan = viper::dataset::readPlan(o.plan);
  } catch (const std::exception& e) {
    std::cerr << "generate: " << e.what() << "\n";
    return 2;
  }
  if (o.merge) {
    try {
      const viper::dataset::MergeResult m = viper::dataset::mergeDataset(plan, o.sequence.root);
      for (const std::string& why : m.missing) std::cerr << "generate: missing " << why << "\n";
      if (!m.missing.empty()) {
        std::cerr << "generate: " << m.missing.size() << " of " << plan.sequences.size()
                  << " planned sequences are not finished: no manifest written\n";
        return 2;
      }
      std::cout << "generate: " << o.sequence.root << ": " << m.sequences << " sequences, " << m.frames << " frames, "
                << m.files << " files: MANIFEST.sha256 and manifest.md written\n";
      return viper_tools::writeDatasetStatistics("generate", o.sequence.root, viper::dataset::planSequences(plan),
                                                 class_table, plan.name);
    } catch (const std::exception& e) {
      std::cerr << "generate: " << e.what() << "\n";
      return 2;
    }
  }
  if (!shard(o, index, count, shard_error)) {
    std::cerr << "generate: " << shard_error << "\n";
    return 2;
  }
  // capture and world sit beside this command.
  const std::filesystem::path bin = std::filesystem::read_symlink("/proc/self/exe").parent_path();
  const std::filesystem::path captures = std::filesystem::path(o.sequence.root) / ".captures";
  int worst = 0;
  const std::vector<viper::dataset::PlannedSequence> mine = viper::dataset::shardOf(plan, index, count);
  std::cout << "generate: plan " << plan.name << ", task " << index << " of " << count << ": " << mine.size()
            << " of " << plan.sequences.size() << " sequences\n";
  for (const viper::dataset::PlannedSequence& q : mine) {
    viper::SequenceSettings s = o.sequence;
    s.split = q.split;
    s.seq = q.id;
    const auto lock = lockSequence(s.root, q.split, q.id);  // until this sequence's capture is removed
    if (!lock) {
      worst = 2;
      continue;
    }
    const std::filesystem::path vcap = captures / (q.split + "_" + q.id + ".vcap");
    const std::filesystem::path log = captures / (q.split + "_" + q.id + ".log");
    viper::StageTimes before;  // the world under capture and its labels, before the frames
    // Without --labels, the world's own oracle of the run labels the meshes it drew (each
    // sequence's town, or part of the city, has meshes of its own).
    const std::filesystem::path oracle = captures / (q.split + "_" + q.id + ".oracle");
    const std::string oracle_option = o.labels.empty() ? " --oracle " + oracle.string() : "";
    // A plan's city: the route stays in the sequence's region, the scenery is the city's.
    const std::string city = plan.city ? " --city-seed " + std::to_string(plan.city->seed) + " --region " +
                                             plan.regionOf(q).text()
                                       : "";
    auto open = [&]() -> std::unique_ptr<viper::RawFrames> {
      std::filesystem::create_directories(captures);
      // The capture is read back once and removed: LZ4 writes and reads it several times faster than
      // zstd, for a larger temporary file (docs/dataset_generation.md#speed).
      const std::string command =
          (bin / "capture").string() + " --codec lz4 --output " + vcap.string() + " --profile " + package +
          "/config/profiles/world.yaml --condition " + q.condition + " --fps " + std::to_string(plan.fps) + " -- " +
          (bin / "world").string() + " --condition " + q.condition + " --ego " + q.ego + " --seed " +
          std::to_string(q.seed) + " --frames " + std::to_string(q.frames) + " --width " + std::to_string(q.width) +
          " --height " + std::to_string(q.height) + " --fps " + std::to_string(plan.fps) + city + oracle_option + " > " + log.string() +
          " 2>&1";
      const ChildClock clock;
      const int rc = std::system(command.c_str());
      clock.addTo(before, "world+capture");
      if (rc != 0) throw std::runtime_error("the world under capture failed; its output is in " + log.string());
      return std::make_unique<viper::CaptureRawFrames>(vcap.string());
    };
    auto labels = [&] {
      if (!o.labels.empty()) return viper::LabelTable::load(o.labels);
      viper::StageTimer t(&before, "labels");
      size_t frames = 0;
      viper::LabelTable table = viper::labelTableFromOracle(vcap.string(), oracle.string(), &frames);
      std::filesystem::remove(oracle);
      std::cout << "generate: " << q.split << "/" << q.id << ": " << table.size() << " mesh labels from the world's oracle ("
                << frames << " frames)\n";
      return table;
    };
    const int code = oneSequence(o, s, class_table, labels, "the world (" + q.condition + ", " + q.ego + ", seed " +
                                 std::to_string(q.seed) + ")", open, before);
    std::error_code ec;
    std::filesystem::remove(vcap, ec);
    std::filesystem::remove(oracle, ec);
    if (code != 2) std::filesystem::remove(log, ec);
    worst = std::max(worst, code);
  }
  {
    std::error_code ec;
    std::filesystem::remove(captures, ec);  // only if empty
  }
  return worst;
}
