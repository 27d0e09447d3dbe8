#include "viper/ros/ground_truth/odometry_node.h"
#include "viper/ros/node_params.h"


namespace viper {
Odometry::Odometry(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), log_([this](StepInput input) {
        return input == StepInput::kDraws ? draws_sub_.getTopic() : std::string(defaultTopicOf(input));
      }) {}

bool Odometry::start() {
  const std::string me = private_nh_.getNamespace();
  OdometrySettings settings;
  private_nh_.param<std::string>("map_frame", settings.map_frame, settings.map_frame);
  private_nh_.param<std::string>("body_frame", settings.body_frame, settings.body_frame);
  private_nh_.param("publish_tf", publish_tf_, true);
  private_nh_.param("path_max_poses", settings.path_max_poses, settings.path_max_poses);
  if (settings.path_max_poses < 1) {
    ROS_ERROR("%s: ~path_max_poses must be >= 1 (got %d); using 10000", me.c_str(), settings.path_max_poses);
    settings.path_max_poses = 10000;
  }
  try {
    step_ = std::make_unique<OdometryMessageStep>(settings);
  } catch (const std::invalid_argument& e) {
    ROS_FATAL("%s: ~%s", me.c_str(), e.what());
    return false;
  }
  const int queue_size = queueSizeParam(private_nh_);
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", queue_size);
  path_pub_ = nh_.advertise<nav_msgs::Path>("path", 1, true);
  if (publish_tf_) {
    tf_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    static_tf_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  }
  draws_sub_ = nh_.subscribe("draws", queue_size, &Odometry::onDraws, this);
  return true;
}

void Odometry::onDraws(const DrawList::ConstPtr& draws) {
  const CpuMeter::Scope cpu(cpu_, true);
  OdometryMessageStep::Output out;
  StepProblems problems;
  const bool kept = step_->process(*draws, out, problems);
  log_.log(problems);
  if (!kept) return;
  if (publish_tf_) {
    tf_->sendTransform(out.map_to_body);
    if (out.optical_changed) static_tf_->sendTransform(out.body_to_optical);
  }
  odom_pub_.publish(out.odom);
  path_pub_.publish(out.path);
}

}  // namespace viper
