#include "viper/ros/dataset/sequence_generator.h"

#include "viper/dataset/file_digests.h"
#include "viper/dataset/sequence_marker.h"
#include "viper/ros/bridge/bag_writer.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/dataset/export_roles.h"

#include <boost/make_shared.hpp>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <memory>
#include <stdexcept>

namespace viper {
namespace fs = std::filesystem;

namespace {

// Frames a frame's late parts (its forward flow) may trail before the exporter completes it.
constexpr uint64_t kFlushWindow = 2;

// The files a sequence owns under ROOT (relative paths), whether or not they exist yet.
std::vector<fs::path> sequencePaths(const SequenceSettings& s) {
  std::vector<fs::path> out;
  for (const char* m : {"img", "cls", "inst", "flow", "flowbw", "bb"}) out.push_back(fs::path(s.split) / m / s.seq);
  out.push_back(fs::path(s.split) / "camera" / (s.seq + ".csv"));
  out.push_back(fs::path(s.split) / "bag" / (s.seq + ".bag"));
  return out;
}

// The ground-truth bag of a sequence: the raw topics as the bridge publishes them and the ground
// truth as the nodes of replay.launch publish it.
class GroundTruthBag {
 public:
  GroundTruthBag(const std::string& path, const std::string& compression) : bag_(path, compression, "/generate") {}

  // The bag numbers header.seq as a publisher would; nothing reads a message's seq after it.
  void writeRaw(const FrameMessages& m) { writeRawFrame(bag_, "/capture", m); }

  void writeGroundTruth(const GroundTruthMessages& g, const ClassTable& classes) {
    const InstancesStep::Output& i = g.instances;
    if (i.semantic) bag_.write("/ground_truth/semantic", i.semantic);
    if (i.semantic_color) bag_.write("/ground_truth/semantic_color", i.semantic_color);
    if (i.instance_ids) bag_.write("/ground_truth/instance_ids", i.instance_ids);
    if (i.boundaries) bag_.write("/ground_truth/boundaries", i.boundaries);
    if (i.instances_viper) bag_.write("/ground_truth/instances_viper", i.instances_viper);
    if (i.objects) bag_.write("/ground_truth/objects", i.objects);
    if (g.boxes.in_map) {
      // The markers carry the boxes' header, as numbered in this bag (whatever the input numbered).
      const Box3DArrayPtr& boxes = g.boxes.in_map;
      bag_.write("/ground_truth/boxes", boxes);
      auto markers = boost::make_shared<visualization_msgs::MarkerArray>(boxMarkers(*boxes, classes));
      bag_.writeAt("/ground_truth/box_markers", boxes->header.stamp, markers);
    }
    if (g.boxes.in_optical) bag_.write("/ground_truth/boxes_optical", g.boxes.in_optical);
    if (g.odometry) {
      bag_.write("/ground_truth/odom", g.odometry->odom);
      auto tf = boost::make_shared<tf2_msgs::TFMessage>();
      tf->transforms.push_back(g.odometry->map_to_body);
      bag_.writeAt("/tf", g.odometry->map_to_body.header.stamp, tf);
      if (g.odometry->optical_changed) {
        auto tf_static = boost::make_shared<tf2_msgs::TFMessage>();
        tf_static->transforms.push_back(g.odometry->body_to_optical);
        bag_.writeAt("/tf_static", g.odometry->body_to_optical.header.stamp, tf_static, /*latched=*/true);
      }
    }
    flow("/ground_truth/flow/forward", g.flow.forward);
    flow("/ground_truth/flow/backward", g.flow.backward);
    flow("/ground_truth/flow/wide", g.flow.wide);
  }

  void close() { bag_.close(); }

 private:
  void flow(const std::string& topic, const FlowMessages& m) {
    if (!m.flow) return;
    bag_.write(topic, m.flow);
    bag_.write(topic + "_visible", m.visible);
  }
  BagWriter bag_;
};

}  // namespace

SequenceGenerator::SequenceGenerator(SequenceSettings settings, LabelTable labels, ClassTable classes)
    : settings_(std::move(settings)), labels_(std::move(labels)), classes_(std::move(classes)) {}

fs::path SequenceGenerator::markerPath() const {
  return fs::path(settings_.root) / settings_.split / (settings_.seq + ".done");
}

bool SequenceGenerator::finished(std::string* why_not) const {
  const fs::path marker = markerPath();
  std::string why;
  if (!fs::exists(marker)) {
    why = marker.string() + " does not exist";
  } else {
    try {
      why = dataset::verifySequence(settings_.root, dataset::readSequenceMarker(marker));
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  if (why_not) *why_not = why;
  return why.empty();
}

SequenceResult SequenceGenerator::run(RawFrames& input, bool force,
                                      const std::function<void(uint64_t, uint64_t)>& progress) {
  SequenceResult result;
  result.marker = markerPath();
  if (!force && finished()) {
    result.skipped = true;
    return result;
  }
  const std::string name = settings_.split + "/" + settings_.seq;
  const fs::path root = settings_.root;
  const fs::path partial = root / ".partial" / (settings_.split + "_" + settings_.seq);
  std::error_code ec;
  fs::remove(markerPath(), ec);
  fs::remove_all(partial, ec);
  fs::create_directories(partial / settings_.split, ec);
  if (ec) throw std::runtime_error("sequence " + name + ": cannot create " + partial.string() + ": " + ec.message());

  ViperExportOptions layout = settings_.layout;
  layout.root = partial.string();
  layout.split = settings_.split;
  layout.seq = settings_.seq;
  layout.camera = CameraSource::kDraws;
  // The instances step makes the inst image itself (instances_viper): without this the exporter
  // also paired semantic with instance ids and encoded and wrote every inst file a second time.
  layout.inputs.instances_viper = true;
  // The layout's files are hashed by their writers; the bag is read back for its checksum (its
  // header, rewritten at close, comes first in the hash).
  dataset::FileDigests digests;
  layout.digests = &digests;
  std::unique_ptr<ViperExporter> exporter;
  if (settings_.outputs.layout) exporter = std::make_unique<ViperExporter>(layout);
  std::unique_ptr<GroundTruthBag> bag;
  if (settings_.outputs.bag) {
    fs::create_directories(partial / settings_.split / "bag");
    bag = std::make_unique<GroundTruthBag>((partial / settings_.split / "bag" / (settings_.seq + ".bag")).string(),
                                           settings_.outputs.bag_compression);
  }

  // With writer threads, the bag is written by one more, in frame order (one thread, a queue).
  std::unique_ptr<dataset::WriteQueue> bag_writer;
  if (bag && settings_.layout.writer_threads > 0) bag_writer = std::make_unique<dataset::WriteQueue>(1, 2, "viper-bag");

  GroundTruthPipeline pipeline(labels_, classes_, settings_.ground_truth);
  std::map<ros::Time, uint64_t> frame_of;  // header stamp -> frame number in the sequence
  FrameMessages raw;
  GroundTruthMessages gt;
  uint64_t read = 0;
  auto problem = [&](const std::string& text) { result.problems.push_back("sequence " + name + ": " + text); };
  StageTimes* times = &result.stages;
  auto next = [&] {
    StageTimer t(times, "read");
    return input.next(raw);
  };
  while ((settings_.max_frames == 0 || read < settings_.max_frames) && next()) {
    ++read;
    const uint64_t frame = frame_of.size();
    const ros::Time stamp = raw.draws->header.stamp;
    frame_of.emplace(stamp, frame);
    StepProblems problems;
    const bool kept = pipeline.process(raw, gt, problems, times);
    for (const StepProblem& p : problems) {
      const std::string text = "sequence " + name + ": frame " + std::to_string(frame) + ": " + defaultTopicOf(p.input) + p.text;
      if (p.severity == StepSeverity::kError) result.problems.push_back(text);
      else if (p.severity == StepSeverity::kWarning) result.warnings.push_back(text);
    }
    if (!kept) ++result.dropped;
    try {
      if (bag) {
        StageTimer t(times, "bag");
        // The frame's messages are new every frame and only read from here on (the bag numbers
        // their header.seq, which nothing else reads), so a thread of its own may write them.
        auto write = [&bag = *bag, raw, gt = kept ? gt : GroundTruthMessages(), kept, classes = pipeline.classes()] {
          bag.writeRaw(raw);
          if (kept) bag.writeGroundTruth(gt, classes);
          return std::string();
        };
        if (bag_writer) bag_writer->submit(write);
        else write();
      }
      if (exporter) {
        StageTimer t(times, "layout");
        auto dispatch = [&](const ExportDispatch& d, const ros::Time& at) {
          const auto f = frame_of.find(at);
          if (f == frame_of.end()) return;
          const std::string bad = d(*exporter, f->second);
          if (!bad.empty()) problem("frame " + std::to_string(f->second) + ": " + bad);
        };
        dispatch(exportDispatch("color", raw.color), stamp);
        dispatch(exportDispatch("draws", raw.draws), stamp);
        if (kept) {
          const InstancesStep::Output& i = gt.instances;
          dispatch(exportDispatch("semantic", i.semantic), stamp);
          // bb's 2D boxes come from the objects: the instance ids would only be copied and scanned
          // for boxes nobody reads (inst comes ready-made, above).
          if (!i.objects) dispatch(exportDispatch("instance_ids", i.instance_ids), stamp);
          dispatch(exportDispatch("instances_viper", i.instances_viper), stamp);
          dispatch(exportDispatch("objects", i.objects), stamp);
          if (gt.boxes.in_optical) dispatch(exportDispatch("boxes", gt.boxes.in_optical), stamp);
          if (gt.flow.forward.flow) dispatch(exportDispatch("flow", gt.flow.forward.flow), gt.flow.forward.flow->header.stamp);
          if (gt.flow.backward.flow) dispatch(exportDispatch("flowbw", gt.flow.backward.flow), stamp);
        }
        if (frame >= kFlushWindow)
          for (const std::string& n : exporter->flushUpTo(frame - kFlushWindow)) problem(n);
      }
    } catch (const std::exception& e) {
      throw std::runtime_error("sequence " + name + ", frame " + std::to_string(frame) + ": " + e.what() +
                               " (the partial sequence stays in " + partial.string() + ")");
    }
    ++result.frames;
    if (progress) progress(result.frames, settings_.max_frames ? std::min(settings_.max_frames, input.frameCount())
                                                               : input.frameCount());
  }
  for (const std::string& p : input.problems()) problem(p);
  for (const std::string& w : input.warnings()) result.warnings.push_back("sequence " + name + ": " + w);
  try {
    StageTimer t(times, "finish");
    if (exporter)
      for (const std::string& n : exporter->finish()) problem(n);
    if (bag_writer) bag_writer->drain();
    if (bag) bag->close();
  } catch (const std::exception& e) {
    throw std::runtime_error("sequence " + name + ": " + e.what() + " (the partial sequence stays in " +
                             partial.string() + ")");
  }
  if (exporter && exporter->writerCpuSeconds() > 0) times->add("layout writers", exporter->writerCpuSeconds(), 0.0);
  if (bag_writer) times->add("bag writer", bag_writer->workerCpuSeconds(), 0.0);
  if (result.frames == 0) throw std::runtime_error("sequence " + name + ": the input has no frame");

  // Into place: the sequence's old files go, the new ones come, the marker last.
  StageTimer into_place(times, "marker");
  dataset::SequenceMarker marker;
  marker.frames = result.frames;
  for (const fs::path& rel : sequencePaths(settings_)) {
    fs::remove_all(root / rel, ec);
    if (!fs::exists(partial / rel)) continue;
    fs::create_directories((root / rel).parent_path(), ec);
    fs::rename(partial / rel, root / rel, ec);
    if (ec)
      throw std::runtime_error("sequence " + name + ": cannot move " + (partial / rel).string() + " to " +
                               (root / rel).string() + ": " + ec.message());
    std::vector<fs::path> files;
    if (fs::is_directory(root / rel)) {
      for (const auto& e : fs::recursive_directory_iterator(root / rel))
        if (e.is_regular_file()) files.push_back(e.path());
    } else {
      files.push_back(root / rel);
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      const fs::path relative = fs::relative(f, root);
      std::string sha256 = digests.find(partial / relative, fs::file_size(f));
      if (sha256.empty()) {
        sha256 = dataset::sha256OfFile(f);
        ++result.checksums_read_back;
      }
      marker.files.push_back({relative.string(), sha256});
    }
  }
  result.files = marker.files.size();
  dataset::writeSequenceMarker(markerPath(), marker);
  fs::remove_all(partial, ec);
  fs::remove(root / ".partial", ec);  // only if empty
  return result;
}

}  // namespace viper
