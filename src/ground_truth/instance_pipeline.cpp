#include "viper/ground_truth/instance_pipeline.h"

#include "pixel_kernels.h"

#include <stdexcept>

namespace viper {

std::vector<bool> InstancePipelineOptions::defaultThingClasses() {
  std::vector<bool> v(256, false);
  for (int c : {13, 16, 17, 19, 20, 23, 24, 25, 26, 27}) v[c] = true;
  return v;
}

InstancePipeline::InstancePipeline(LabelTable labels, InstancePipelineOptions options)
    : labels_(std::move(labels)), options_(std::move(options)), tracker_(options_.tracker) {}

InstanceFrame InstancePipeline::process(const CaptureFrame& frame) {
  InstanceFrame out;
  process(frame, out);
  return out;
}

void InstancePipeline::process(const CaptureFrame& frame, InstanceFrame& out) { process(frame, out, {}); }

void InstancePipeline::renderPictures(const DrawAssignment& a, const std::vector<int32_t>& instance_of_draw,
                                      const InstanceImagesInto& into) const {
  const size_t n = a.draw_class.size();
  // Per draw id (0: no draw), as renderSemantic and renderInstances give them.
  const auto classOf = [&](size_t id) -> uint8_t { return id != 0 && id <= n ? a.draw_class[id - 1] : 0; };
  std::vector<std::array<uint8_t, 3>> colors(n + 1);
  if (into.semantic_color) {
    const ClassTable& classes = *into.classes;
    const auto colorOf = [&](uint8_t c) { return c < classes.size() ? classes.at(c).rgb : std::array<uint8_t, 3>{}; };
    for (size_t id = 0; id <= n; ++id) colors[id] = colorOf(classOf(id));
    renderRgbOfDraws(runs_, colors, colorOf(0), into.semantic_color);
  }
  if (into.instances_viper) {
    for (size_t id = 0; id <= n; ++id) {
      const uint32_t t = static_cast<uint32_t>(instance_of_draw[id]) & 0xffffu;
      colors[id] = {classOf(id), static_cast<uint8_t>(t >> 8), static_cast<uint8_t>(t & 0xff)};
    }
    renderRgbOfDraws(runs_, colors, {0, 0, 0}, into.instances_viper);
  }
}

void InstancePipeline::process(const CaptureFrame& frame, InstanceFrame& out, const InstanceImagesInto& into) {
  // Only draws and draw ids are used (a node may have nothing else); ids past the draw list are
  // ignored by every kernel, so they need no pass of their own.
  const std::string at = "frame " + std::to_string(frame.number) + ": ";
  if (into.semantic_color && !into.classes)
    throw std::invalid_argument(at + "semantic_color asked for without classes");
  if (!into.draw_ids && frame.draw_ids.size() != frame.pixelCount())
    throw std::invalid_argument(at + "draw id image has " + std::to_string(frame.draw_ids.size()) + " pixels, " +
                                std::to_string(frame.width) + "x" + std::to_string(frame.height) + " expected");
  for (size_t i = 0; i < frame.draws.size(); ++i)
    if (frame.draws[i].index != i)
      throw std::invalid_argument(at + "draw " + std::to_string(i) + " has index " +
                                  std::to_string(frame.draws[i].index) + " (must be 0..n-1 in order)");
  meshes_.add(frame.new_meshes);

  out.objects.clear();
  out.problems.clear();
  VoteWeight weight;
  if (options_.area_weighted_vote) {
    weight = [this](const DrawRecord& d) {
      const double a = meshes_.area(d.mesh_key);
      return a > 0.0 ? a : 1e-6;  // a part of unknown area still votes, below any real one
    };
  }
  std::vector<FrameObject> objects = groupObjects(frame, labels_, options_.thing_classes, weight);
  std::vector<FrameObject> kept;
  for (FrameObject& o : objects) {
    if (o.world.allFinite()) {
      kept.push_back(std::move(o));
    } else {
      out.problems.push_back("frame " + std::to_string(frame.number) + ": object of draw " +
                             std::to_string(o.draws.front()) + " has a non-finite world matrix; skipped");
    }
  }
  objects.swap(kept);
  attachParts(objects, frame, meshes_);
  const DrawAssignment assignment = assignDraws(frame, labels_, objects);
  findDrawRuns(frame, into.draw_ids ? into.draw_ids : frame.draw_ids.data(), runs_);
  measureObjects(runs_, assignment, objects);

  std::vector<Eigen::Vector3d> positions;
  for (const FrameObject& o : objects) positions.push_back(o.world.block<3, 1>(0, 3).cast<double>());
  const std::vector<int32_t> ids = tracker_.update(frame.time_s, objects, positions);
  out.tracker_reset = tracker_.wasReset();

  const size_t n = frame.pixelCount();
  out.semantic.resize(into.semantic ? 0 : n);
  out.instance_ids.resize(into.instance_ids ? 0 : n);
  out.boundaries.resize(into.boundaries ? 0 : n);
  int32_t* instance_ids = into.instance_ids ? into.instance_ids : out.instance_ids.data();
  renderSemantic(runs_, assignment, into.semantic ? into.semantic : out.semantic.data());
  // The instances, boundaries and pictures from the runs of draws (the same bytes as from the images).
  const std::vector<int32_t> instance_of_draw = instanceOfDraws(assignment, ids);
  renderInstances(runs_, instance_of_draw, instance_ids);
  renderBoundariesOfRuns(runs_, instance_of_draw, into.boundaries ? into.boundaries : out.boundaries.data());
  renderPictures(assignment, instance_of_draw, into);

  for (size_t k = 0; k < objects.size(); ++k) {
    TrackedObject t;
    t.track_id = ids[k];
    if (objects[k].is_thing && options_.compute_boxes) {
      t.box = objectBox(frame, objects[k], meshes_, &t.box_status);
      if (t.box_status == BoxStatus::kMissingMesh)
        out.problems.push_back("frame " + std::to_string(frame.number) + ": track " + std::to_string(ids[k]) +
                               ": no mesh of its parts has arrived; no box");
    }
    t.object = std::move(objects[k]);
    out.objects.push_back(std::move(t));
  }
}

void encodeViperInstances(const uint8_t* class_ids, const int32_t* instance_ids, size_t n, uint8_t* rgb,
                          Instructions instructions) {
  // The kernel's blocks, then one pixel at a time: the reference, and the pixels after the blocks.
  const Instructions path = pixel_kernels::kernelPath(instructions);
  const size_t done = path == Instructions::kScalar ? 0
                                                    : pixel_kernels::encodeViper(path, class_ids, instance_ids, n, rgb);
  for (size_t i = done; i < n; ++i) {
    const uint32_t id = static_cast<uint32_t>(instance_ids[i]) & 0xffffu;
    rgb[3 * i] = class_ids[i];
    rgb[3 * i + 1] = static_cast<uint8_t>(id >> 8);
    rgb[3 * i + 2] = static_cast<uint8_t>(id & 0xff);
  }
}

}  // namespace viper
