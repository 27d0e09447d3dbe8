// The segmentation baseline's model (docs/baselines.md): a small fully convolutional network
// trained by scripts/train_segmentation.py, run with OpenCV's DNN module, and the instance baseline
// made from its output. No ROS: the nodelet (include/viper/ros/baselines/segmentation_baseline.h)
// and the tests call this.
#pragma once

#include "viper/ground_truth/class_table.h"

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace viper {

/// What the network says about one image, at the image's size.
struct Segmentation {
  cv::Mat class_ids;   ///< CV_8UC1: VIPER class id of each pixel (config/viper_classes.csv)
  cv::Mat confidence;  ///< CV_32FC1: softmax probability of that class, in (0, 1]
};

/// An ONNX network whose output channels are the class table's train ids (0 .. n-1), in the
/// convention of scripts/train_segmentation.py: input N x 3 x H x W, RGB scaled to [0, 1];
/// output N x n x H x W scores (logits).
class SegmentationModel {
 public:
  /// Loads the model. `input_size`: the size images are resized to before the network (width and
  /// height multiples of 8: the network's stride). Throws std::runtime_error naming the file when it
  /// cannot be read, or when the class table's train ids are not 0 .. n-1 or do not match the
  /// network's n outputs (checked with one run on a black image).
  SegmentationModel(const std::string& onnx_path, const ClassTable& classes, cv::Size input_size);

  /// Segments an RGB image (CV_8UC3, any size): resized to inputSize(), run, the scores resized back
  /// bilinearly, each pixel the class of its highest score. Throws std::invalid_argument for another
  /// type or an empty image.
  Segmentation segment(const cv::Mat& rgb);

  cv::Size inputSize() const { return input_size_; }
  /// Number of classes the network scores (its output channels).
  int outputClasses() const { return static_cast<int>(class_of_channel_.size()); }

 private:
  cv::Mat scores(const cv::Mat& rgb);  ///< the network's 1 x n x H x W output for one image

  cv::dnn::Net net_;
  cv::Size input_size_;
  std::vector<uint8_t> class_of_channel_;  ///< output channel (train id) -> class id
};

/// One predicted instance: a connected region of one class.
struct InstanceSegment {
  uint8_t class_id = 0;
  float score = 0;  ///< the mean confidence of its pixels
  cv::Rect box;     ///< in the image
  cv::Mat mask;     ///< CV_8UC1 of the box's size, 255 inside, 0 outside
  int pixels = 0;
};

/// The instance baseline: every 8-connected region of pixels of one class with `instance_class[id]`
/// (the class table's instanceEvalMask()) and at least `min_pixels` pixels is an instance, scored by
/// its pixels' mean confidence. Ordered by class, then as cv::connectedComponentsWithStats numbers
/// the regions.
std::vector<InstanceSegment> instancesFromSegmentation(const Segmentation& segmentation,
                                                       const std::vector<bool>& instance_class, int min_pixels);

}  // namespace viper
