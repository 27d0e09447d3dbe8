#include "viper/ground_truth/stamp_order.h"

#include <cstdio>

namespace viper {

bool stampAfterLast(const FrameStamp& last, const FrameStamp& stamp, uint64_t number, StepInput input,
                    StepProblems& problems) {
  if (last.isZero() || last < stamp) return true;
  char text[160];
  std::snprintf(text, sizeof text, ": frame %lu stamp %.6f is not after the previous %.6f; frame dropped",
                static_cast<unsigned long>(number), stamp.seconds(), last.seconds());
  problems.push_back({input, StepSeverity::kError, "stamp_order", text});
  return false;
}

}  // namespace viper
