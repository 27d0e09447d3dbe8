// The instances node's per-frame work on messages: its draw list and draw id image decoded into a
// frame, the core InstancesStep (include/viper/ground_truth/instances_step.h) run on it, and its
// objects and images as messages (ground_truth_conversions.h, which `generate` converts with too).
#pragma once

#include "viper/ground_truth/instances_step.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

namespace viper {

class InstancesMessageStep {
 public:
  /// Throws std::invalid_argument if a setting is out of range (extrapolate_frames < 0).
  InstancesMessageStep(LabelTable labels, ClassTable classes, const InstancesSettings& settings)
      : step_(std::move(labels), std::move(classes), settings) {}

  void addMeshes(const MeshStore& store, StepProblems& problems);

  /// A frame's outputs, each with the draw id image's header; null where not wanted.
  struct Output {
    sensor_msgs::ImagePtr semantic, semantic_color, instance_ids, boundaries, instances_viper;
    ObjectArrayPtr objects;
  };
  /// One frame (draw list and draw id image of one stamp). Returns false if it was dropped.
  bool process(const DrawList& draws, const sensor_msgs::ImageConstPtr& draw_ids, const InstanceImagesWanted& want,
               Output& out, StepProblems& problems);
  /// The class id image of the last frame processed (for the overlay; made whether wanted or not).
  const sensor_msgs::ImageConstPtr& lastSemantic() const { return last_semantic_; }
  /// The overlay of class colors over a camera image (rgb8) of the class id image's size, or null
  /// with a problem if it does not fit.
  sensor_msgs::ImagePtr overlay(const sensor_msgs::Image& color, const sensor_msgs::Image& semantic, float alpha,
                                StepProblems& problems);

  const ClassTable& classes() const { return step_.classes(); }

 private:
  InstancesStep step_;
  GroundTruthInput input_;  // reused between frames (its draws' storage)
  InstanceFrame result_;    // reused between frames; its images go into messages
  InstanceImagePools pools_;
  sensor_msgs::ImageConstPtr last_semantic_;
};

}  // namespace viper
