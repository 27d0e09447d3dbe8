// The ground-truth nodes' mesh_store input, taken the same way by instances, boxes and flow.
#pragma once

#include "viper/ros/ground_truth/step_log.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <viper/MeshStore.h>

#include <memory>
#include <mutex>

namespace viper {

/// Adds the meshes of `store` to `step` (its addMeshes, under `mutex`, the lock that guards the
/// step) and logs what it reports with `log`; the CPU it takes counts in `cpu`, not as a frame's.
template <typename Step>
void addMeshStore(const MeshStore& store, const std::unique_ptr<Step>& step, std::mutex& mutex, CpuMeter& cpu,
                  StepLog& log) {
  const CpuMeter::Scope scope(cpu, false);
  StepProblems problems;
  {
    std::lock_guard<std::mutex> lock(mutex);
    step->addMeshes(store, problems);
  }
  log.log(problems);
}

}  // namespace viper
