#include "viper/ros/dataset/sequence_generator.h"

#include "viper/dataset/file_digests.h"
#include "viper/dataset/training_export.h"
#include "viper/dataset/sequence_marker.h"
#include "viper/ros/bridge/bag_writer.h"
#include "viper/ros/conversions/amodal_conversions.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/ground_truth/labelled_cloud_node.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <memory>
#include <optional>
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
  out.push_back(fs::path(s.split) / "training" / s.seq);
  return out;
}

// The training formats' sequence number of a sequence name of 1 to 6 digits.
uint32_t trainingSequenceNumber(const std::string& seq) {
  if (seq.empty() || seq.size() > 6 || seq.find_first_not_of("0123456789") != std::string::npos)
    throw std::runtime_error("the training formats (cityscapes, coco, kitti) number sequences: the sequence name "
                             "must be 1 to 6 digits, got '" + seq + "'");
  return static_cast<uint32_t>(std::stoul(seq));
}

// The training formats' writer of a sequence, or null when none is asked for.
std::unique_ptr<dataset::TrainingExport> trainingExport(const SequenceSettings& s, const fs::path& partial,
                                                        const ClassTable& classes) {
  if (!s.outputs.cityscapes && !s.outputs.coco && !s.outputs.kitti) return nullptr;
  dataset::TrainingExportOptions t;
  t.root = (partial / s.split / "training" / s.seq).string();
  t.cityscapes = s.outputs.cityscapes;
  t.coco = s.outputs.coco;
  t.kitti = s.outputs.kitti;
  t.split = s.split;
  t.sequence = trainingSequenceNumber(s.seq);
  t.images = s.layout.images;
  for (const auto& c : classes.classes())
    if (c.instance_eval) t.categories.push_back({c.id, c.name, "viper"});
  return std::make_unique<dataset::TrainingExport>(t);
}

// The ground truth of one frame as the nodes of replay.launch publish it, each null where a step
// dropped the frame or made nothing.
struct GroundTruthMessages {
  InstanceImageMessages images;  // semantic, semantic_color, instance_ids, boundaries, instances_viper
  ObjectArrayPtr objects;
  BoxesMessages boxes;           // in map and in the optical frame
  std::optional<OdometryMessages::Output> odometry;
  FlowMessages flow_forward, flow_backward, flow_wide;  // between the previous frame and this one
  // The modalities asked for (--modalities), as their nodes publish them.
  sensor_msgs::ImagePtr normals, scene_flow;  // scene_flow: the previous frame -> this one
  sensor_msgs::PointCloud2Ptr cloud;
  AmodalInstanceArrayPtr amodal;
};

// A new float image of `frame`'s size and header (its draw ids'), `channels` floats a pixel.
sensor_msgs::ImagePtr floatImage(const GroundTruthInput& frame, const std::string& encoding, uint32_t channels) {
  auto image = boost::make_shared<sensor_msgs::Image>();
  image->header = headerOf(frame);
  image->width = frame.frame.width, image->height = frame.frame.height;
  image->encoding = encoding;
  image->step = 4 * channels * image->width;
  image->data.resize(static_cast<size_t>(image->step) * image->height);
  return image;
}

// The normals' and the cloud's messages of a frame (new ones each frame: the bag's thread may still
// hold the last), shaped as the normals and labelled_cloud nodes shape theirs.
class ModalityMessages : public ModalitySink {
 public:
  float* takeNormals(const GroundTruthInput& frame) override {
    normals = floatImage(frame, sensor_msgs::image_encodings::TYPE_32FC3, 3);
    return reinterpret_cast<float*>(normals->data.data());
  }
  CloudPoint* takeCloud(const GroundTruthInput&, const CloudSize& size) override {
    cloud = boost::make_shared<sensor_msgs::PointCloud2>();
    shapeLabelledCloudMsg(size, *cloud);
    return reinterpret_cast<CloudPoint*>(cloud->data.data());
  }
  sensor_msgs::ImagePtr normals;
  sensor_msgs::PointCloud2Ptr cloud;
};

// The flows' messages, and the scene flow's (32FC4, with the header of the frame it starts from, as
// the flow node's).
class FlowAndSceneFlowMessages : public FlowMessagePools {
 public:
  float* takeSceneFlow(const GroundTruthInput& from) override {
    scene_flow = floatImage(from, sensor_msgs::image_encodings::TYPE_32FC4, 4);
    return reinterpret_cast<float*>(scene_flow->data.data());
  }
  sensor_msgs::ImagePtr scene_flow;
};

// The ground-truth bag of a sequence: the raw topics as the bridge publishes them and the ground
// truth as the nodes of replay.launch publish it.
class GroundTruthBag {
 public:
  GroundTruthBag(const std::string& path, const std::string& compression) : bag_(path, compression, "/generate") {}

  // The bag numbers header.seq as a publisher would; nothing reads a message's seq after it.
  void writeRaw(const FrameMessages& m) { writeRawFrame(bag_, "/capture", m); }

  void writeGroundTruth(const GroundTruthMessages& g, const ClassTable& classes) {
    const InstanceImageMessages& i = g.images;
    if (i.semantic) bag_.write("/ground_truth/semantic", i.semantic);
    if (i.semantic_color) bag_.write("/ground_truth/semantic_color", i.semantic_color);
    if (i.instance_ids) bag_.write("/ground_truth/instance_ids", i.instance_ids);
    if (i.boundaries) bag_.write("/ground_truth/boundaries", i.boundaries);
    if (i.instances_viper) bag_.write("/ground_truth/instances_viper", i.instances_viper);
    if (g.objects) bag_.write("/ground_truth/objects", g.objects);
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
    flow("/ground_truth/flow/forward", g.flow_forward);
    flow("/ground_truth/flow/backward", g.flow_backward);
    flow("/ground_truth/flow/wide", g.flow_wide);
    if (g.scene_flow) bag_.write("/ground_truth/flow/scene_flow", g.scene_flow);
    if (g.normals) bag_.write("/ground_truth/normals", g.normals);
    if (g.cloud) bag_.write("/ground_truth/labelled_cloud", g.cloud);
    if (g.amodal) bag_.write("/ground_truth/amodal/objects", g.amodal);
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

// One kept frame into the training formats: its images, depth and amodal masks as frame `at`, and
// the forward flow its step made (from the previous frame) as that frame's.
void writeTrainingFrame(dataset::TrainingExport& training, uint64_t at, const FrameMessages& raw,
                        const GroundTruthInput& decoded, const InstanceImageMessages& images,
                        const GroundTruthResult& truth, const FlowMessages& forward,
                        const std::map<ros::Time, uint64_t>& frame_of) {
  const uint32_t w = decoded.frame.width, h = decoded.frame.height;
  dataset::TrainingFrame f;
  f.frame = static_cast<uint32_t>(at);
  std::optional<dataset::ImageView8> rgb;
  if (raw.color && raw.color->encoding == sensor_msgs::image_encodings::RGB8 && raw.color->width == w &&
      raw.color->height == h && raw.color->step == 3 * w)
    rgb.emplace(raw.color->data.data(), w, h, 3);
  f.rgb = rgb ? &*rgb : nullptr;
  f.class_ids = images.semantic->data.data();
  f.instance_ids = reinterpret_cast<const int32_t*>(images.instance_ids->data.data());
  f.width = w, f.height = h;
  f.depth_m = decoded.depth_m;
  std::vector<dataset::TrainingAmodalMask> amodal;
  for (const AmodalObject& o : truth.amodal.objects)
    if (!o.box.empty())
      amodal.push_back({o.track_id, o.class_id, o.box.x_min, o.box.y_min, static_cast<uint32_t>(o.box.width()),
                        static_cast<uint32_t>(o.box.height()), o.mask.data()});
  f.amodal = &amodal;
  training.addFrame(f);
  if (!truth.flow.forward) return;
  const auto from = frame_of.find(toRosTime(truth.flow.forward_from));
  if (from == frame_of.end() || !forward.flow) return;
  dataset::FlowImage flow;
  flow.width = forward.flow->width, flow.height = forward.flow->height;
  const float* uv = reinterpret_cast<const float*>(forward.flow->data.data());
  flow.uv.assign(uv, uv + 2 * flow.pixels());
  dataset::TrainingFrame g;
  g.frame = static_cast<uint32_t>(from->second);
  g.flow = &flow;
  training.addFrame(g);
}

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

  std::unique_ptr<dataset::TrainingExport> training = trainingExport(settings_, partial, classes_);
  GroundTruthSettings ground_truth = settings_.ground_truth;
  ground_truth.amodal = ground_truth.amodal || settings_.outputs.coco;  // COCO's amodal file
  GroundTruthPipeline pipeline(labels_, classes_, ground_truth);
  // The ground truth's messages, made as the nodes make them (ground_truth_conversions.h).
  OdometrySettings odometry = settings_.odometry;
  odometry.make_path = false;  // the bag and the layout keep the poses; a path per frame is O(n^2)
  OdometryMessages odometry_messages(odometry);
  InstanceImagePools image_pools;
  FlowAndSceneFlowMessages flow_pools;
  GroundTruthResult truth;  // kept from frame to frame: its storage
  std::map<ros::Time, uint64_t> frame_of;  // header stamp -> frame number in the sequence
  FrameMessages raw;
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
    StepProblems problems, flow_input_problems;
    GroundTruthMessages gt;
    InstanceImagesInto into;
    // The frame decoded once, for every step: its draws, and its images' pixels where they are.
    auto decoded = std::make_shared<GroundTruthInput>();
    {
      StageTimer t(times, "decode");
      const unsigned long number = raw.draws->frame_number;
      if (raw.mesh_store) {
        std::vector<std::string> bad;
        pipeline.addMeshes(fromMeshStoreMsg(*raw.mesh_store, bad, &pipeline.meshes()));
        for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
      }
      const std::string ids_problem = decodeDrawMsgs(*raw.draws, raw.draw_ids, *decoded);
      if (!ids_problem.empty()) {
        problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "frame",
                            " (frame " + std::to_string(number) + ", frame_id '" + raw.draw_ids->header.frame_id +
                                "'): " + ids_problem + "; frame dropped"});
      } else {
        if (settings_.ground_truth.flow_enabled || settings_.outputs.kitti || settings_.ground_truth.normals ||
            settings_.ground_truth.cloud_decimation > 0) {
          std::string depth_problem, primitives_problem;
          decodeFlowMsgs(raw.depth, raw.primitive_ids, *decoded, depth_problem, primitives_problem);
          const std::string at = " (frame " + std::to_string(number) + "): ";
          if (!depth_problem.empty())
            flow_input_problems.push_back({StepInput::kDepth, StepSeverity::kError, "depth", at + depth_problem + "; frame dropped"});
          else if (!primitives_problem.empty())
            flow_input_problems.push_back({StepInput::kPrimitiveIds, StepSeverity::kError, "primitive_ids",
                                           at + primitives_problem + "; frame dropped"});
        }
        if (raw.color && raw.color->encoding == sensor_msgs::image_encodings::RGB8 &&
            raw.color->width == decoded->frame.width && raw.color->height == decoded->frame.height &&
            raw.color->step == 3 * raw.color->width)
          decoded->color_rgb = raw.color->data.data();  // the cloud's colours (raw.color outlives the frame)
        // The instance images are computed into the messages the bag and the layout take.
        gt.images = image_pools.take(headerOf(*decoded), decoded->frame.width, decoded->frame.height,
                                     InstanceImagesWanted(), into);
      }
    }
    flow_pools.clear();
    flow_pools.scene_flow.reset();
    ModalityMessages modalities;
    const bool kept = pipeline.process(decoded, into, flow_pools, truth, problems, times, &modalities);
    problems.insert(problems.end(), flow_input_problems.begin(), flow_input_problems.end());
    {
      StageTimer t(times, "messages");
      if (truth.ego) gt.odometry = odometry_messages.convert(*truth.ego, raw.draws->header);
      if (kept) {
        gt.objects = boost::make_shared<ObjectArray>(
            toObjectArrayMsg(truth.instances.objects, pipeline.classes(), headerOf(*decoded)));
        gt.boxes = toBoxesMsgs(truth.boxes, raw.draws->header, odometry.map_frame, pipeline.classes());
        if (truth.flow.forward) gt.flow_forward = flow_pools.messages(FlowKind::kForward);
        if (truth.flow.backward) gt.flow_backward = flow_pools.messages(FlowKind::kBackward);
        if (truth.flow.wide) gt.flow_wide = flow_pools.messages(FlowKind::kWide);
        if (truth.flow.scene_flow) gt.scene_flow = flow_pools.scene_flow;
        if (truth.normals) gt.normals = modalities.normals;
        if (truth.cloud) {
          gt.cloud = modalities.cloud;
          gt.cloud->header = raw.depth->header;
        }
        if (settings_.ground_truth.amodal)
          gt.amodal = boost::make_shared<AmodalInstanceArray>(toAmodalInstanceArrayMsg(truth.amodal, headerOf(*decoded)));
      }
    }
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
        // The frame's parts by the frame number of their stamp (its first frame's, if it came again).
        const uint64_t at = frame_of.find(stamp)->second;
        auto note = [&](uint64_t f, const std::string& bad) {
          if (!bad.empty()) problem("frame " + std::to_string(f) + ": " + bad);
        };
        // The camera image as the raw frame brings it (a message, read where it is); the ground
        // truth as the pipeline made it, its images in the messages the bag takes too.
        note(at, exporter->addColor(at, raw.color));
        ViperLayoutWriter& layout_writer = exporter->writer();
        note(at, layout_writer.addCamera(at, truth.camera));
        if (kept) {
          auto image = [](const sensor_msgs::ImagePtr& m, uint32_t channels) {
            return dataset::ImageView8(m->data.data(), m->width, m->height, channels);
          };
          auto flow = [&](uint64_t f, const FlowMessages& m, bool backward) {
            note(f, layout_writer.addFlow(f, reinterpret_cast<const float*>(m.flow->data.data()), m.flow->width,
                                          m.flow->height, messageOwner(m.flow), backward));
          };
          const InstanceImageMessages& i = gt.images;
          note(at, layout_writer.addSemantic(at, image(i.semantic, 1), messageOwner(i.semantic)));
          // bb's 2D boxes come from the objects (inst comes ready-made, above).
          note(at, layout_writer.addInstancesViper(at, image(i.instances_viper, 3), messageOwner(i.instances_viper)));
          note(at, layout_writer.addObjects(at, objectBoxes2d(truth.instances.objects)));
          if (truth.boxes.has_optical) note(at, layout_writer.addBoxesOptical(at, viperBoxes(truth.boxes)));
          if (truth.flow.forward) {
            const auto from = frame_of.find(toRosTime(truth.flow.forward_from));
            if (from != frame_of.end()) flow(from->second, gt.flow_forward, false);
          }
          if (truth.flow.backward) flow(at, gt.flow_backward, true);
        }
        if (frame >= kFlushWindow)
          for (const std::string& n : exporter->flushUpTo(frame - kFlushWindow)) problem(n);
      }
      if (training && kept) {
        StageTimer t(times, "training");
        writeTrainingFrame(*training, frame_of.find(stamp)->second, raw, *decoded, gt.images, truth, gt.flow_forward,
                           frame_of);
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
    if (training) training->finish();
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
