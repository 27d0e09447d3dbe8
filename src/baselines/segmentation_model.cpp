#include "viper/baselines/segmentation_model.h"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace viper {

SegmentationModel::SegmentationModel(const std::string& onnx_path, const ClassTable& classes, cv::Size input_size)
    : input_size_(input_size) {
  if (input_size.width < 8 || input_size.height < 8 || input_size.width % 8 || input_size.height % 8)
    throw std::runtime_error("segmentation model: input size " + std::to_string(input_size.width) + "x" +
                             std::to_string(input_size.height) + " (width and height must be multiples of 8)");
  std::vector<int> class_of(classes.size(), -1);
  for (const ClassInfo& c : classes.classes()) {
    if (c.train_id == 255) continue;
    if (c.train_id < 0 || static_cast<size_t>(c.train_id) >= classes.size() || class_of[c.train_id] >= 0)
      throw std::runtime_error("segmentation model: class table: train id " + std::to_string(c.train_id) + " of '" +
                               c.name + "' out of range or taken twice");
    class_of[c.train_id] = c.id;
  }
  for (size_t t = 0; t < class_of.size() && class_of[t] >= 0; ++t) class_of_channel_.push_back(uint8_t(class_of[t]));
  for (size_t t = class_of_channel_.size(); t < class_of.size(); ++t)
    if (class_of[t] >= 0)
      throw std::runtime_error("segmentation model: class table: train ids skip " +
                               std::to_string(class_of_channel_.size()));
  try {
    net_ = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("segmentation model " + onnx_path + ": " + e.what());
  }
  if (net_.empty()) throw std::runtime_error("segmentation model " + onnx_path + ": no network in the file");
  const cv::Mat out = scores(cv::Mat::zeros(input_size_, CV_8UC3));
  if (out.dims != 4 || out.size[1] != outputClasses() || out.size[2] != input_size_.height ||
      out.size[3] != input_size_.width)
    throw std::runtime_error("segmentation model " + onnx_path + ": output " + std::to_string(out.size[1]) +
                             " channels of " + std::to_string(out.size[3]) + "x" + std::to_string(out.size[2]) +
                             ", expected " + std::to_string(outputClasses()) + " (the class table's train ids) of " +
                             std::to_string(input_size_.width) + "x" + std::to_string(input_size_.height));
}

cv::Mat SegmentationModel::scores(const cv::Mat& rgb) {
  // The network was trained on RGB in [0, 1]; blobFromImage resizes bilinearly.
  net_.setInput(cv::dnn::blobFromImage(rgb, 1.0 / 255.0, input_size_, cv::Scalar(), false, false, CV_32F));
  return net_.forward().clone();  // forward's result is the network's own buffer
}

Segmentation SegmentationModel::segment(const cv::Mat& rgb) {
  if (rgb.empty() || rgb.type() != CV_8UC3)
    throw std::invalid_argument("segmentation model: image must be a non-empty CV_8UC3 RGB image");
  const cv::Mat out = scores(rgb);
  const int n = outputClasses();
  std::vector<cv::Mat> planes(n);
  for (int c = 0; c < n; ++c) {
    const cv::Mat plane(out.size[2], out.size[3], CV_32F, const_cast<float*>(out.ptr<float>(0, c)));
    if (plane.size() == rgb.size()) planes[c] = plane;
    else cv::resize(plane, planes[c], rgb.size(), 0, 0, cv::INTER_LINEAR);
  }
  Segmentation s{cv::Mat(rgb.size(), CV_8UC1), cv::Mat(rgb.size(), CV_32FC1)};
  std::vector<const float*> row(n);
  for (int y = 0; y < rgb.rows; ++y) {
    for (int c = 0; c < n; ++c) row[c] = planes[c].ptr<float>(y);
    uint8_t* ids = s.class_ids.ptr<uint8_t>(y);
    float* conf = s.confidence.ptr<float>(y);
    for (int x = 0; x < rgb.cols; ++x) {
      int best = 0;
      for (int c = 1; c < n; ++c)
        if (row[c][x] > row[best][x]) best = c;
      // Softmax of the best class: 1 / sum_c exp(s_c - s_best), each term <= 1.
      double sum = 0;
      for (int c = 0; c < n; ++c) sum += std::exp(double(row[c][x]) - row[best][x]);
      ids[x] = class_of_channel_[best];
      conf[x] = float(1.0 / sum);
    }
  }
  return s;
}

std::vector<InstanceSegment> instancesFromSegmentation(const Segmentation& segmentation,
                                                       const std::vector<bool>& instance_class, int min_pixels) {
  std::vector<InstanceSegment> out;
  bool present[256] = {};
  for (int y = 0; y < segmentation.class_ids.rows; ++y) {
    const uint8_t* ids = segmentation.class_ids.ptr<uint8_t>(y);
    for (int x = 0; x < segmentation.class_ids.cols; ++x) present[ids[x]] = true;
  }
  cv::Mat labels, stats, centroids;
  for (size_t c = 0; c < instance_class.size() && c < 256; ++c) {
    if (!instance_class[c] || !present[c]) continue;
    const cv::Mat of_class = segmentation.class_ids == static_cast<int>(c);
    const int count = cv::connectedComponentsWithStats(of_class, labels, stats, centroids, 8, CV_32S);
    for (int k = 1; k < count; ++k) {
      const int area = stats.at<int>(k, cv::CC_STAT_AREA);
      if (area < min_pixels) continue;
      InstanceSegment inst;
      inst.class_id = static_cast<uint8_t>(c);
      inst.box = cv::Rect(stats.at<int>(k, cv::CC_STAT_LEFT), stats.at<int>(k, cv::CC_STAT_TOP),
                          stats.at<int>(k, cv::CC_STAT_WIDTH), stats.at<int>(k, cv::CC_STAT_HEIGHT));
      inst.mask = labels(inst.box) == k;
      inst.score = static_cast<float>(cv::mean(segmentation.confidence(inst.box), inst.mask)[0]);
      inst.pixels = area;
      out.push_back(std::move(inst));
    }
  }
  return out;
}

}  // namespace viper
