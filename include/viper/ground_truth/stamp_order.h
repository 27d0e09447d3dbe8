// The check that frames come in stamp order, for the steps that keep the last frame's stamp.
#pragma once

#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/step_problems.h"

#include <cstdint>

namespace viper {

/// Whether frame `number` of `stamp` comes after `last` (the last frame processed; zero: none
/// yet). If not, adds a "stamp_order" error on `input` to `problems`: the frame is dropped.
bool stampAfterLast(const FrameStamp& last, const FrameStamp& stamp, uint64_t number, StepInput input,
                    StepProblems& problems);

}  // namespace viper
