// The instances node's per-frame work without ROS plumbing: objects, classes, tracks and the
// segmentation images of one frame, as messages. The instances node and the lockstep `generate`
// both run it (docs/ground_truth_nodes.md).
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/label_table.h"
#include "viper/ros/conversions/image_msg_pool.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <memory>
#include <vector>

namespace viper {

/// Settings of the instances step (the instances node's parameters, with the same defaults).
struct InstancesSettings {
  bool area_weighted_vote = true;
  int extrapolate_frames = 10;
  double lod_tolerance_m = 0.05;
  bool resume_tracks_by_resources = false;
};

class InstancesStep {
 public:
  /// Throws std::invalid_argument if a setting is out of range (extrapolate_frames < 0).
  InstancesStep(LabelTable labels, ClassTable classes, const InstancesSettings& settings);

  void addMeshes(const MeshStore& store, StepProblems& problems);

  /// Which images to make (objects are always made).
  struct Want {
    bool semantic = true, semantic_color = true, instance_ids = true, boundaries = true, instances_viper = true;
  };
  /// A frame's outputs, each with the draw id image's header; null where not wanted.
  struct Output {
    sensor_msgs::ImagePtr semantic, semantic_color, instance_ids, boundaries, instances_viper;
    ObjectArrayPtr objects;
  };
  /// One frame (draw list and draw id image of one stamp). Returns false if it was dropped.
  bool process(const DrawList& draws, const sensor_msgs::Image& draw_ids, const Want& want, Output& out,
               StepProblems& problems);
  /// The class id image of the last frame processed (for the overlay; made whether wanted or not).
  const sensor_msgs::ImageConstPtr& lastSemantic() const { return last_semantic_; }
  /// The overlay of class colors over a camera image (rgb8) of the class id image's size, or null
  /// with a problem if it does not fit.
  sensor_msgs::ImagePtr overlay(const sensor_msgs::Image& color, const sensor_msgs::Image& semantic, float alpha,
                                StepProblems& problems);

  const ClassTable& classes() const { return classes_; }

 private:
  ClassTable classes_;
  std::unique_ptr<InstancePipeline> pipeline_;
  CaptureFrame frame_;    // reused between frames
  InstanceFrame result_;  // reused between frames; its images go into messages
  ImageMsgPool ids_pool_, mono_pool_, rgb_pool_{24};  // the images' messages, recycled
  ros::Time last_stamp_;
  sensor_msgs::ImageConstPtr last_semantic_;
};

}  // namespace viper
