// The odometry part of the submission layout: estimates into KITTI's axes. Apart from the rest of
// viper_submission.cpp because it takes the optical frame from the ground truth's ego-motion
// (viper_core), which the file writers of viper_dataset do not link.
#include "viper/dataset/viper_submission.h"
#include "viper/ground_truth/ego_motion.h"

#include <stdexcept>

namespace viper::dataset {

std::vector<SubmissionPose> kittiSubmissionPoses(const std::vector<double>& timestamps_s,
                                                 const std::vector<Eigen::Isometry3d>& estimates,
                                                 bool estimates_are_optical) {
  if (timestamps_s.size() != estimates.size())
    throw std::invalid_argument("kittiSubmissionPoses: " + std::to_string(timestamps_s.size()) + " timestamps for " +
                                std::to_string(estimates.size()) + " poses");
  const Eigen::Isometry3d to_optical = estimates_are_optical ? Eigen::Isometry3d::Identity() : bodyFromOptical();
  std::vector<SubmissionPose> poses;
  if (estimates.empty()) return poses;
  const Eigen::Isometry3d first_inverse = (estimates.front() * to_optical).inverse();
  for (size_t i = 0; i < estimates.size(); ++i) {
    const Eigen::Isometry3d kitti = first_inverse * estimates[i] * to_optical;
    SubmissionPose p;
    p.timestamp_s = timestamps_s[i];
    p.position = kitti.translation();
    p.orientation = Eigen::Quaterniond(kitti.rotation()).normalized();
    poses.push_back(p);
  }
  return poses;
}

}  // namespace viper::dataset
