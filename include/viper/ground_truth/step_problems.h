// What a ground-truth step (the per-frame work of a node, shared with the lockstep `generate`) says
// about its inputs: which input, how bad, in words. The node logs each with its input's topic,
// throttled per kind (StepLog); `generate` reports it with the sequence and frame.
#pragma once

#include <string>
#include <vector>

namespace viper {

/// The inputs of the ground-truth steps (the raw capture topics and the instances step's objects).
enum class StepInput { kDraws, kDrawIds, kDepth, kPrimitiveIds, kObjects, kMeshStore, kColor };

/// How bad: kInfo (nothing lost: a loop starts over), kWarning (an output is missing or partial),
/// kError (the frame, or part of its ground truth, is dropped).
enum class StepSeverity { kInfo, kWarning, kError };

/// One problem. `text` follows the input's name: "(frame 12): ...; frame dropped" or ": ...".
/// `kind` is a short fixed key (e.g. "stamp_order"), for throttling one kind at a time.
struct StepProblem {
  StepInput input;
  StepSeverity severity;
  const char* kind;
  std::string text;
};
using StepProblems = std::vector<StepProblem>;

}  // namespace viper
