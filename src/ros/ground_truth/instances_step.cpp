#include "viper/ros/ground_truth/instances_step.h"

#include "viper/ground_truth/semantic_overlay.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/object_conversions.h"

#include <boost/make_shared.hpp>

namespace viper {

void InstancesMessageStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  step_.addMeshes(fromMeshStoreMsg(store, bad, &step_.meshes()));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

bool InstancesMessageStep::process(const DrawList& draws, const sensor_msgs::ImageConstPtr& ids,
                                   const InstanceImagesWanted& want, Output& out, StepProblems& problems) {
  out = Output();
  if (!step_.inOrder(toFrameStamp(draws.header.stamp), draws.frame_number, problems)) return false;
  // The draw ids are read where they are, in their message.
  const std::string problem = decodeDrawMsgs(draws, ids, input_);
  if (!problem.empty()) {
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "frame",
                        " (frame " + std::to_string(draws.frame_number) + ", frame_id '" + ids->header.frame_id +
                            "'): " + problem + "; frame dropped"});
    return false;
  }
  // The images are computed into the messages that carry them (every pixel written: recycled
  // messages need no clearing).
  const std_msgs::Header& header = ids->header;
  InstanceImagesInto into;
  InstanceImageMessages images = pools_.take(header, input_.frame.width, input_.frame.height, want, into);
  if (!step_.process(input_.frame, input_.stamp, input_.draw_ids, into, result_, problems)) return false;
  last_semantic_ = images.semantic;
  if (want.semantic) out.semantic = images.semantic;
  out.semantic_color = images.semantic_color;
  out.instance_ids = images.instance_ids;
  out.boundaries = images.boundaries;
  out.instances_viper = images.instances_viper;
  out.objects = boost::make_shared<ObjectArray>(toObjectArrayMsg(result_.objects, step_.classes(), header));
  return true;
}

sensor_msgs::ImagePtr InstancesMessageStep::overlay(const sensor_msgs::Image& color, const sensor_msgs::Image& semantic,
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
  sensor_msgs::ImagePtr overlay = pools_.takeRgb(color.header, color.width, color.height);
  overlayClasses(color.data.data(), semantic.data.data(), n, step_.classes(), alpha, overlay->data.data());
  return overlay;
}

}  // namespace viper
