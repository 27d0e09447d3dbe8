#include "viper/ros/baselines/vo_baseline.h"

#include "viper/ground_truth/ego_motion.h"
#include "viper/ros/baselines/image_input.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace viper {
namespace {

// Ground truth is only looked up by exact stamp; older entries than this many are forgotten.
constexpr size_t kMaxGroundTruth = 300;

}  // namespace

VoBaseline::VoBaseline(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
    : nh_(nh), private_nh_(private_nh) {}

bool VoBaseline::start() {
  private_nh_.param("map_frame", map_frame_, map_frame_);
  private_nh_.param("child_frame_id", child_frame_, child_frame_);
  private_nh_.param("scale_from_ground_truth", scale_from_gt_, scale_from_gt_);
  private_nh_.param("max_features", max_features_, max_features_);
  private_nh_.param("min_inliers", min_inliers_, min_inliers_);
  private_nh_.param("ransac_threshold_px", ransac_threshold_px_, ransac_threshold_px_);
  private_nh_.param("max_pending", max_pending_, max_pending_);
  private_nh_.param("forward_backward_px", fb_threshold_px_, fb_threshold_px_);
  private_nh_.param("min_parallax_px", min_parallax_px_, min_parallax_px_);
  private_nh_.param("queue_size", queue_size_, queue_size_);
  if (max_features_ < 8 || min_inliers_ < 5 || !(ransac_threshold_px_ > 0) || !(fb_threshold_px_ > 0) || max_pending_ < 1 ||
      queue_size_ < 1) {
    ROS_FATAL("vo_baseline: need ~max_features >= 8, ~min_inliers >= 5, ~ransac_threshold_px > 0, "
              "~forward_backward_px > 0, ~max_pending >= 1, ~queue_size >= 1 (got %d, %d, %g, %g, %d, %d)", max_features_,
              min_inliers_, ransac_threshold_px_, fb_threshold_px_, max_pending_, queue_size_);
    return false;
  }
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 50);
  info_sub_ = nh_.subscribe("camera_info", 10, &VoBaseline::onCameraInfo, this);
  if (scale_from_gt_) gt_sub_ = nh_.subscribe("ground_truth_odom", 50, &VoBaseline::onGroundTruth, this);
  image_sub_ = nh_.subscribe("image", static_cast<uint32_t>(queue_size_), &VoBaseline::onImage, this);
  ROS_INFO("vo_baseline: %s -> %s (scale %s)", image_sub_.getTopic().c_str(), odom_pub_.getTopic().c_str(),
           scale_from_gt_ ? ("from " + gt_sub_.getTopic()).c_str() : "unknown: unit steps");
  return true;
}

void VoBaseline::onCameraInfo(const sensor_msgs::CameraInfo::ConstPtr& msg) {
  const auto& k = msg->K;
  if (!(k[0] > 0 && k[4] > 0 && std::isfinite(k[2]) && std::isfinite(k[5]))) {
    ROS_ERROR_THROTTLE(5, "vo_baseline: %s: K has no positive focal lengths: ignored", info_sub_.getTopic().c_str());
    return;
  }
  K_ = cv::Matx33d(k[0], k[1], k[2], k[3], k[4], k[5], k[6], k[7], k[8]);
}

void VoBaseline::onGroundTruth(const nav_msgs::Odometry::ConstPtr& msg) {
  gt_[msg->header.stamp] = fromPoseMsg(msg->pose.pose);
  while (gt_.size() > kMaxGroundTruth) gt_.erase(gt_.begin());
  processPending();
}

void VoBaseline::onImage(const sensor_msgs::Image::ConstPtr& msg) {
  if (!scale_from_gt_) {
    pending_[msg->header.stamp] = msg;
    processPending();
    return;
  }
  pending_[msg->header.stamp] = msg;
  while (static_cast<int>(pending_.size()) > max_pending_) {
    ROS_WARN_THROTTLE(5, "vo_baseline: no ground truth on %s for frame %.6f: dropped",
                      gt_sub_.getTopic().c_str(), pending_.begin()->first.toSec());
    pending_.erase(pending_.begin());
  }
  processPending();
}

void VoBaseline::processPending() {
  while (!pending_.empty()) {
    const auto first = pending_.begin();
    if (scale_from_gt_ && !gt_.count(first->first)) {
      // Ground truth comes in stamp order: if a later one is there, this frame's never will be.
      if (gt_.empty() || gt_.rbegin()->first < first->first) return;
      ROS_WARN_THROTTLE(5, "vo_baseline: no ground truth on %s for frame %.6f: dropped",
                        gt_sub_.getTopic().c_str(), first->first.toSec());
      pending_.erase(first);
      continue;
    }
    const sensor_msgs::Image::ConstPtr msg = first->second;
    pending_.erase(first);
    try {
      cv::Mat gray;
      std::string error;
      if (!grayFromImage(*msg, gray, error)) {
        ROS_ERROR_THROTTLE(5, "vo_baseline: %s: frame %.6f dropped: %s", image_sub_.getTopic().c_str(),
                           msg->header.stamp.toSec(), error.c_str());
        continue;
      }
      step(msg, gray);
    } catch (const std::exception& e) {
      ROS_ERROR_THROTTLE(5, "vo_baseline: %s: frame %.6f dropped: %s", image_sub_.getTopic().c_str(),
                         msg->header.stamp.toSec(), e.what());
    }
  }
}

void VoBaseline::step(const sensor_msgs::Image::ConstPtr& msg, const cv::Mat& gray) {
  const ros::Time stamp = msg->header.stamp;
  if (!K_) {
    ROS_ERROR_THROTTLE(5, "vo_baseline: %s: frame %.6f dropped: no camera_info yet on %s",
                       image_sub_.getTopic().c_str(), stamp.toSec(), info_sub_.getTopic().c_str());
    return;
  }
  if (have_prev_ && stamp <= prev_stamp_) {
    ROS_ERROR_THROTTLE(5, "vo_baseline: %s: frame %.6f dropped: stamp not after the previous %.6f",
                       image_sub_.getTopic().c_str(), stamp.toSec(), prev_stamp_.toSec());
    return;
  }
  auto newKeyframe = [&] {
    kf_gray_ = gray;
    kf_stamp_ = stamp;
    kf_map_from_optical_ = map_from_optical_;
    kf_points_.clear();
    cv::goodFeaturesToTrack(gray, kf_points_, max_features_, 0.01, 8);
  };
  if (!have_prev_ || gray.size() != prev_gray_.size()) {
    if (have_prev_)
      ROS_ERROR_THROTTLE(5, "vo_baseline: %s: size changed at %.6f: tracking starts over",
                         image_sub_.getTopic().c_str(), stamp.toSec());
    // The trajectory starts at the ground-truth pose (where there is one) so both share one map frame.
    const auto gt = gt_.find(stamp);
    map_from_optical_ = gt != gt_.end() ? gt->second * bodyFromOptical() : Eigen::Isometry3d::Identity();
    newKeyframe();
  } else {
    // Tracks from the keyframe, not the previous image: a few pixels of motion per frame leave the
    // essential matrix's translation ill-conditioned, so the pose is estimated only once the tracks
    // have moved ~min_parallax_px; frames in between keep the keyframe's pose.
    std::vector<cv::Point2f> p1, back;
    std::vector<uchar> status, back_status;
    std::vector<float> err;
    if (!kf_points_.empty()) {
      cv::calcOpticalFlowPyrLK(kf_gray_, gray, kf_points_, p1, status, err, cv::Size(21, 21), 3);
      // Forward-backward check: tracks that do not return to their corner (rain streaks, occlusion
      // edges, textureless drift) are dropped before RANSAC.
      cv::calcOpticalFlowPyrLK(gray, kf_gray_, p1, back, back_status, err, cv::Size(21, 21), 3);
    }
    std::vector<cv::Point2f> a, b;
    std::vector<float> moved;
    for (size_t i = 0; i < status.size(); ++i) {
      if (!status[i] || !back_status[i]) continue;
      const cv::Point2f d = back[i] - kf_points_[i];
      if (d.dot(d) > fb_threshold_px_ * fb_threshold_px_) continue;
      a.push_back(kf_points_[i]), b.push_back(p1[i]);
      moved.push_back(static_cast<float>(cv::norm(p1[i] - kf_points_[i])));
    }
    float parallax = 0;
    if (!moved.empty()) {
      std::nth_element(moved.begin(), moved.begin() + moved.size() / 2, moved.end());
      parallax = moved[moved.size() / 2];
    }
    if (static_cast<int>(a.size()) < min_inliers_) {
      ROS_WARN_THROTTLE(5, "vo_baseline: %s: frame %.6f: tracking lost (%zu tracks, need %d): pose kept, new keyframe",
                        image_sub_.getTopic().c_str(), stamp.toSec(), a.size(), min_inliers_);
      newKeyframe();
    } else if (parallax >= min_parallax_px_) {
      int inliers = 0;
      cv::Mat R, t;
      cv::Mat mask;
      cv::Mat E = cv::findEssentialMat(a, b, cv::Mat(*K_), cv::RANSAC, 0.999, ransac_threshold_px_, mask);
      // Several solutions come stacked; the first is RANSAC's best.
      if (E.rows >= 3 && E.cols == 3) inliers = cv::recoverPose(E.rowRange(0, 3), a, b, cv::Mat(*K_), R, t, mask);
      double scale = 1.0;
      if (scale_from_gt_) {
        const auto g0 = gt_.find(kf_stamp_), g1 = gt_.find(stamp);
        scale = (g0 != gt_.end() && g1 != gt_.end())
                    ? (g1->second.translation() - g0->second.translation()).norm()
                    : std::numeric_limits<double>::quiet_NaN();
      }
      if (inliers < min_inliers_ || !std::isfinite(scale)) {
        ROS_WARN_THROTTLE(5, "vo_baseline: %s: frame %.6f: %s (%d inliers of %zu tracks, need %d): pose kept",
                          image_sub_.getTopic().c_str(), stamp.toSec(),
                          std::isfinite(scale) ? "tracking failed" : "no ground-truth step length", inliers,
                          a.size(), min_inliers_);
      } else {
        // recoverPose: x_cur = R x_kf + t, with |t| = 1.
        Eigen::Isometry3d cur_from_kf = Eigen::Isometry3d::Identity();
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) cur_from_kf.linear()(r, c) = R.at<double>(r, c);
          cur_from_kf.translation()(r) = t.at<double>(r) * scale;
        }
        map_from_optical_ = kf_map_from_optical_ * cur_from_kf.inverse();
      }
      newKeyframe();
    }
  }
  prev_gray_ = gray;
  prev_stamp_ = stamp;
  have_prev_ = true;
  publish(msg->header);
}

void VoBaseline::publish(const std_msgs::Header& header) {
  const Eigen::Isometry3d map_from_body = map_from_optical_ * bodyFromOptical().inverse();
  nav_msgs::Odometry odom;
  odom.header.stamp = header.stamp;
  odom.header.frame_id = map_frame_;
  odom.child_frame_id = child_frame_;
  odom.pose.pose = toPoseMsg(map_from_body);
  odom_pub_.publish(odom);
}

}  // namespace viper
