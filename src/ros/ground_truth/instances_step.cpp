#include "viper/ros/ground_truth/instances_step.h"

#include "viper/ground_truth/semantic_overlay.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/object_conversions.h"

#include <boost/make_shared.hpp>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace viper {

InstancesStep::InstancesStep(LabelTable labels, ClassTable classes, const InstancesSettings& settings)
    : classes_(std::move(classes)) {
  if (settings.extrapolate_frames < 0)
    throw std::invalid_argument("extrapolate_frames must be >= 0 (got " + std::to_string(settings.extrapolate_frames) + ")");
  InstancePipelineOptions options;
  options.thing_classes = classes_.instanceEvalMask();
  options.thing_classes.resize(256, false);
  options.area_weighted_vote = settings.area_weighted_vote;
  options.compute_boxes = false;  // the boxes step makes them
  options.tracker.extrapolate_frames = settings.extrapolate_frames;
  options.tracker.lod_tolerance_m = settings.lod_tolerance_m;
  options.tracker.resume_by_resources = settings.resume_tracks_by_resources;
  pipeline_ = std::make_unique<InstancePipeline>(std::move(labels), options);
}

void InstancesStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  pipeline_->addMeshes(fromMeshStoreMsg(store, bad, &pipeline_->meshes()));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

bool InstancesStep::process(const DrawList& draws, const sensor_msgs::Image& ids, const Want& want, Output& out,
                            StepProblems& problems) {
  out = Output();
  const unsigned long number = draws.frame_number;
  if (!last_stamp_.isZero() && draws.header.stamp <= last_stamp_) {
    char text[160];
    std::snprintf(text, sizeof text, ": frame %lu stamp %.6f is not after the previous %.6f; frame dropped", number,
                  draws.header.stamp.toSec(), last_stamp_.toSec());
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "stamp_order", text});
    return false;
  }
  // The draw ids are read where they are, in their message.
  const uint32_t* id_words = nullptr;
  const std::string problem = frameFromDrawMsgs(draws, ids, frame_, id_words);
  if (!problem.empty()) {
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "frame",
                        " (frame " + std::to_string(number) + ", frame_id '" + ids.header.frame_id + "'): " + problem +
                            "; frame dropped"});
    return false;
  }
  // The images are computed into the messages that carry them (every pixel written: recycled
  // messages need no clearing).
  const std_msgs::Header& header = ids.header;
  const uint32_t w = frame_.width, h = frame_.height;
  // The pipeline renders the instance ids in result_ when nobody wants them (boundaries need them).
  // The class ids always go into a message: the overlay reads them when the color image comes.
  sensor_msgs::ImagePtr semantic = mono_pool_.take(header, w, h, "mono8", 1);
  sensor_msgs::ImagePtr instance_ids = want.instance_ids ? ids_pool_.take(header, w, h, "32SC1", 4) : nullptr;
  sensor_msgs::ImagePtr boundaries = want.boundaries ? mono_pool_.take(header, w, h, "mono8", 1) : nullptr;
  sensor_msgs::ImagePtr semantic_color = want.semantic_color ? rgb_pool_.take(header, w, h, "rgb8", 3) : nullptr;
  sensor_msgs::ImagePtr instances_viper = want.instances_viper ? rgb_pool_.take(header, w, h, "rgb8", 3) : nullptr;
  InstanceImagesInto into;
  into.draw_ids = id_words;
  into.semantic = semantic->data.data();
  if (instance_ids) into.instance_ids = reinterpret_cast<int32_t*>(instance_ids->data.data());
  if (boundaries) into.boundaries = boundaries->data.data();
  // The class and VIPER pictures from the pipeline's runs of draws (colorizeClasses and
  // encodeViperInstances of the images, without reading them again).
  if (semantic_color) into.semantic_color = semantic_color->data.data(), into.classes = &classes_;
  if (instances_viper) into.instances_viper = instances_viper->data.data();
  try {
    pipeline_->process(frame_, result_, into);
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "pipeline", std::string(": ") + e.what() + "; frame dropped"});
    return false;
  }
  last_stamp_ = draws.header.stamp;
  for (const std::string& p : result_.problems)
    problems.push_back({StepInput::kDrawIds, StepSeverity::kWarning, "objects", ": " + p});

  last_semantic_ = semantic;
  if (want.semantic) out.semantic = semantic;
  out.semantic_color = semantic_color;
  out.instance_ids = instance_ids;
  out.boundaries = boundaries;
  out.instances_viper = instances_viper;
  out.objects = boost::make_shared<ObjectArray>(toObjectArrayMsg(result_.objects, classes_, header));
  return true;
}

sensor_msgs::ImagePtr InstancesStep::overlay(const sensor_msgs::Image& color, const sensor_msgs::Image& semantic,
                                             float alpha, StepProblems& problems) {
  const size_t n = static_cast<size_t>(color.width) * color.height;
  std::string problem = checkImage(color, "rgb8");
  if (problem.empty() && semantic.data.size() != n)
    problem = "its " + std::to_string(n) + " pixels do not fit the " + std::to_string(semantic.data.size()) +
              "-pixel semantic image";
  if (!problem.empty()) {
    problems.push_back({StepInput::kColor, StepSeverity::kError, "overlay", ": color image: " + problem + "; no overlay"});
    return nullptr;
  }
  sensor_msgs::ImagePtr overlay = rgb_pool_.take(color.header, color.width, color.height, "rgb8", 3);
  overlayClasses(color.data.data(), semantic.data.data(), n, classes_, alpha, overlay->data.data());
  return overlay;
}

}  // namespace viper
