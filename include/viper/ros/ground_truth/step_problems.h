// The problems a ground-truth step reports (include/viper/ground_truth/step_problems.h), named by the
// topics their inputs arrive on.
#pragma once

#include "viper/ground_truth/step_problems.h"

namespace viper {

/// The raw topic name of an input as replay.launch names it ("/capture/draws", ...).
const char* defaultTopicOf(StepInput input);

}  // namespace viper
