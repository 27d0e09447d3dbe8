// The instances pipeline the world's checks run: VIPER's instance_eval classes as things, the
// world's label table, no boxes.
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/label_table.h"

#include <string>

namespace viper {
namespace test {

inline InstancePipeline worldInstancePipeline(const std::string& labels_yaml, const std::string& classes_csv) {
  InstancePipelineOptions options;
  options.thing_classes = ClassTable::load(classes_csv).instanceEvalMask();
  options.thing_classes.resize(256, false);
  options.compute_boxes = false;
  return InstancePipeline(LabelTable::load(labels_yaml), options);
}

}  // namespace test
}  // namespace viper
