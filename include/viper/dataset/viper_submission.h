// VIPER's submission layout (the devkit's EVALUATION.md, github srrichter/viper): what a user sends
// to the benchmark's server, one folder per task as the devkit's prepare_submission.py takes it:
//
//   <out>/cls/<seq:03d>_<frame:05d>.png                       class ids, 8-bit single-channel PNG
//   <out>/inst/<seq:03d>_<frame:05d>_<class>_<instance>.png   one binary mask per instance
//   <out>/inst/instances.csv                                  sequence,frame,class,instance,confidence
//   <out>/flow/<seq:03d>_<frame:05d>.flo                      Middlebury flow frame -> frame + 1
//   <out>/odometry/<seq:03d>.txt                              timestamp,tx,ty,tz,qx,qy,qz,qw (KITTI axes)
//
// docs/evaluate.md, "Submission files", has the details and where each rule comes from.
#pragma once

#include "viper/dataset/flow_image.h"
#include "viper/dataset/viper_images.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

/// The task folders under a submission's root.
constexpr const char* kSubmissionClsDir = "cls";
constexpr const char* kSubmissionInstDir = "inst";
constexpr const char* kSubmissionFlowDir = "flow";
constexpr const char* kSubmissionOdometryDir = "odometry";

/// "<seq:03d>_<frame:05d>", the name of a frame in every task (VIPER's input image names).
/// Throws std::invalid_argument if `sequence_id` is not in 0..999 or `frame` above 99999.
std::string submissionFrameName(int sequence_id, uint64_t frame);

/// Writes `<dir>/<seq>_<frame>.png`: class ids (1 channel) as an 8-bit grayscale PNG, the gray
/// values being the ids. Returns the path. Throws std::invalid_argument for an image that is not
/// 1 channel, std::runtime_error naming the path if it cannot be written.
std::string writeSubmissionSemantic(const std::string& dir, int sequence_id, uint64_t frame, const Image8& class_ids);

/// One predicted instance of a frame: a full-frame mask (1 channel, non-zero = inside).
struct SubmissionInstance {
  uint8_t class_id = 0;
  double confidence = 0.0;  ///< in [0, 1]
  Image8 mask;
};

/// One row of instances.csv.
struct SubmissionInstanceRow {
  int sequence_id = 0;
  uint64_t frame = 0;
  int class_id = 0;
  int instance_id = 0;  ///< 1, 2, ... per class within a frame
  double confidence = 0.0;
};

/// Writes one mask PNG per instance, `<dir>/<seq>_<frame>_<class>_<instance>.png` (8-bit gray, 255
/// inside, 0 outside), numbering the instances of each class 1, 2, ... in the order given, and
/// returns their rows for instances.csv. Throws std::invalid_argument (naming the instance) for a
/// mask that is not 1 channel of the first mask's size or a confidence outside [0, 1] or not
/// finite, before anything is written; std::runtime_error naming the path if a file cannot be
/// written.
std::vector<SubmissionInstanceRow> writeSubmissionInstances(const std::string& dir, int sequence_id, uint64_t frame,
                                                            const std::vector<SubmissionInstance>& instances);

/// Writes `<dir>/instances.csv`: the rows of other sequences already in the file are kept (so that
/// sequences can be written one after the other), those of `sequence_id` replaced by `rows`, all
/// sorted by sequence, frame, class and instance; no header, "%d,%d,%d,%d,%.9g" as in
/// EVALUATION.md's example ("2,4,24,1,0.75"). Throws std::runtime_error naming the file if it
/// cannot be read or written, or if an existing line is not such a row.
void writeInstancesCsv(const std::string& dir, int sequence_id, const std::vector<SubmissionInstanceRow>& rows);

/// Reads instances.csv (as written above). Throws std::runtime_error naming the file and line.
std::vector<SubmissionInstanceRow> readInstancesCsv(const std::string& path);

/// Writes `<dir>/<seq>_<frame>.flo`, the flow from `frame` to `frame` + 1 (writeMiddleburyFlo).
/// Returns the path.
std::string writeSubmissionFlow(const std::string& dir, int sequence_id, uint64_t frame, const FlowImage& flow);

/// A camera pose of the odometry file, in KITTI's axes.
struct SubmissionPose {
  double timestamp_s = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               ///< tx, ty, tz
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< qx, qy, qz, qw
};

/// Camera poses in KITTI's convention from an estimator's poses (each the camera's pose in the
/// estimator's fixed frame, ordered by time): the optical frame (x right, y down, z forward) of each
/// pose expressed in the optical frame of the first one, so the first pose is the identity.
/// `estimates_are_optical` = false: the estimates are of the camera body frame (x forward, y left,
/// z up; the package's odometry), converted with bodyFromOptical(). Throws std::invalid_argument if
/// the two vectors differ in length.
std::vector<SubmissionPose> kittiSubmissionPoses(const std::vector<double>& timestamps_s,
                                                 const std::vector<Eigen::Isometry3d>& estimates,
                                                 bool estimates_are_optical);

/// Writes `<dir>/<seq:03d>.txt`: one line per pose, "timestamp,tx,ty,tz,qx,qy,qz,qw" (timestamp
/// "%.4f" as the devkit's sequence/timestamp lists write it, the rest "%.9g"). Returns the path.
/// Throws std::runtime_error naming the path if it cannot be written.
std::string writeSubmissionOdometry(const std::string& dir, int sequence_id, const std::vector<SubmissionPose>& poses);

/// Reads an odometry file as written above. Throws std::runtime_error naming the file and line.
std::vector<SubmissionPose> readSubmissionOdometry(const std::string& path);

}  // namespace viper::dataset
