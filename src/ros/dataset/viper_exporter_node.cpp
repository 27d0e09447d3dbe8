#include "viper/ros/dataset/viper_exporter_node.h"

#include <ros/package.h>

#include <cstdio>
#include <sstream>

namespace viper {
namespace {

// Stamps a message may wait for the reference topic to bring them.
constexpr size_t kMaxWaitingStamps = 64;
// Frames a message may trail behind the newest numbered frame before its frame is completed with
// what it has.
constexpr uint64_t kFlushWindow = 30;

}  // namespace

ViperExporterNode::ViperExporterNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
    : nh_(nh), private_nh_(private_nh), from_parameters_(true) {}

ViperExporterNode::ViperExporterNode(const ros::NodeHandle& nh, const LiveExportConfig& config)
    : nh_(nh), private_nh_("~"), from_parameters_(false), config_(config), own_process_(true) {}

ViperExporterNode::~ViperExporterNode() { finish(); }

bool ViperExporterNode::readParameters() {
  const std::string me = private_nh_.getNamespace();
  ViperExportOptions& e = config_.exporter;
  if (!private_nh_.getParam("root", e.root) || e.root.empty()) {
    ROS_FATAL("%s: ~root (the layout's folder) is required", me.c_str());
    return false;
  }
  private_nh_.param("split", e.split, e.split);
  // _seq:=002 on a command line or in a launch file arrives as the integer 2: VIPER's names have three digits.
  int seq_number = 0;
  if (private_nh_.getParam("seq", seq_number)) {
    char name[16];
    std::snprintf(name, sizeof name, "%03d", seq_number);
    e.seq = name;
  } else {
    private_nh_.param("seq", e.seq, e.seq);
  }
  int first_frame = 0;
  private_nh_.param("first_frame", first_frame, 0);
  config_.first_frame = static_cast<uint64_t>(std::max(first_frame, 0));
  private_nh_.param("frames_from", config_.frames_from, config_.frames_from);
  private_nh_.param("img_format", e.image_extension, e.image_extension);
  private_nh_.param("jpeg_quality", e.images.jpeg_quality, e.images.jpeg_quality);
  private_nh_.param("png_level", e.images.png_compression_level, e.images.png_compression_level);
  private_nh_.param("deflate_level", e.zip.deflate_level, e.zip.deflate_level);
  private_nh_.param("camera", config_.camera, config_.camera);
  bool absolute_poses = false;
  private_nh_.param("absolute_poses", absolute_poses, false);
  e.relative_poses = !absolute_poses;
  private_nh_.param("near", e.near_m, e.near_m);
  private_nh_.param("far", e.far_m, e.far_m);
  std::string palette = "viper", class_table = ros::package::getPath("viper") + "/config/viper_classes.csv";
  private_nh_.param("cls_palette", palette, palette);
  private_nh_.param("class_table", class_table, class_table);
  const std::string problem = exportOptionsProblem(e, palette, config_.camera);
  if (!problem.empty()) {
    ROS_FATAL("%s: %s (parameters ~img_format, ~jpeg_quality, ~png_level, ~deflate_level, ~cls_palette, ~camera, "
              "~near, ~far)", me.c_str(), problem.c_str());
    return false;
  }
  if (palette == "viper") {
    try {
      e.palette = classPalette(class_table);
    } catch (const std::exception& ex) {
      ROS_FATAL("%s: ~class_table: %s", me.c_str(), ex.what());
      return false;
    }
  }
  // Topics relative to the node's namespace, so that they can be remapped; roles listed in
  // ~roles_off are not listened to.
  std::string off;
  private_nh_.param("roles_off", off, off);
  std::istringstream words(off);
  for (std::string name; std::getline(words, name, ',');) {
    ExportRole* role = findExportRole(config_.roles, name);
    if (role == nullptr) {
      ROS_FATAL("%s: ~roles_off names '%s', which is none of color, semantic, instance_ids, instances_viper, flow, "
                "flowbw, boxes, objects, draws, odom, camera_info", me.c_str(), name.c_str());
      return false;
    }
    role->topic.clear();
  }
  for (ExportRole& r : config_.roles)
    if (!r.topic.empty() && r.topic[0] == '/') r.topic.erase(0, 1);
  return true;
}

bool ViperExporterNode::start(bool is_node) {
  own_process_ = is_node;
  return start();
}

int ViperExporterNode::exitCode() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failed_ ? 2 : 0;
}

bool ViperExporterNode::start() {
  if (from_parameters_ && !readParameters()) return false;
  const std::string me = private_nh_.getNamespace();
  if (config_.camera == "auto") config_.camera = "draws";
  ViperExportOptions& e = config_.exporter;
  e.camera = cameraSourceOf(config_.camera);
  const auto on = [&](const char* r) { return !exportRole(config_.roles, r).topic.empty(); };
  e.inputs.semantic = on("semantic");
  e.inputs.instance_ids = on("instance_ids");
  e.inputs.instances_viper = false;  // may never come: semantic + instance ids are paired
  e.inputs.objects = on("objects");
  try {
    exporter_ = std::make_unique<ViperExporter>(e);
  } catch (const std::exception& ex) {
    ROS_FATAL("%s: %s", me.c_str(), ex.what());
    return false;
  }
  next_frame_ = config_.first_frame;
  const std::string color = exportRole(config_.roles, "color").topic;
  reference_ = nh_.resolveName(config_.frames_from.empty() ? color : config_.frames_from);
  if (reference_.empty() || (config_.frames_from.empty() && color.empty())) {
    ROS_FATAL("%s: no reference topic: the color role is off and ~frames_from is not set", me.c_str());
    return false;
  }
  for (const ExportRole& r : config_.roles) {
    if (r.topic.empty()) continue;
    if (r.name == "draws" && config_.camera != "draws") continue;
    if ((r.name == "odom" || r.name == "camera_info") && config_.camera != "odom") continue;
    if (r.datatype == "sensor_msgs/Image") subscribe<sensor_msgs::Image>(r);
    else if (r.datatype == "viper/Box3DArray") subscribe<Box3DArray>(r);
    else if (r.datatype == "viper/ObjectArray") subscribe<ObjectArray>(r);
    else if (r.datatype == "viper/DrawList") subscribe<DrawList>(r);
    else if (r.datatype == "nav_msgs/Odometry") subscribe<nav_msgs::Odometry>(r);
    else if (r.datatype == "sensor_msgs/CameraInfo") subscribe<sensor_msgs::CameraInfo>(r);
  }
  finish_srv_ = private_nh_.advertiseService("finish", &ViperExporterNode::onFinish, this);
  ROS_INFO("%s: writing %s/%s sequence %s; frames numbered by %s", me.c_str(), e.root.c_str(), e.split.c_str(),
           e.seq.c_str(), reference_.c_str());
  return true;
}

template <typename M>
void ViperExporterNode::subscribe(const ExportRole& r) {
  const std::string topic = nh_.resolveName(r.topic), name = r.name;
  subs_.push_back(nh_.subscribe<M>(r.topic, 100, [this, topic, name](const boost::shared_ptr<const M>& m) {
    onMessage(topic, m->header.stamp, exportDispatch(name, m));
  }));
}

void ViperExporterNode::onMessage(const std::string& topic, const ros::Time& stamp, const ExportDispatch& dispatch) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (failed_ || finished_) return;
  ++received_;
  auto known = frame_of_.find(stamp);
  if (known == frame_of_.end() && topic == reference_) {
    if (!frame_of_.empty() && stamp < frame_of_.rbegin()->first)
      ROS_WARN_THROTTLE(5, "viper_exporter: %s stamp %s is older than the newest; numbered after it", topic.c_str(),
                        stampText(stamp).c_str());
    known = frame_of_.emplace(stamp, next_frame_++).first;
    newest_ = known->second;
  }
  if (known == frame_of_.end()) {
    if (!frame_of_.empty() && stamp < frame_of_.rbegin()->first) {
      ++dropped_;
      ROS_ERROR_THROTTLE(5, "viper_exporter: dropping %s at stamp %s: %s never had that stamp", topic.c_str(),
                         stampText(stamp).c_str(), reference_.c_str());
      return;
    }
    waiting_[stamp].emplace_back(topic, dispatch);
    while (waiting_.size() > kMaxWaitingStamps) {
      dropped_ += waiting_.begin()->second.size();
      ROS_ERROR_THROTTLE(5, "viper_exporter: dropping messages at stamp %s: %s has not published that stamp",
                         stampText(waiting_.begin()->first).c_str(), reference_.c_str());
      waiting_.erase(waiting_.begin());
    }
    return;
  }
  run(topic, stamp, known->second, dispatch);
  const auto w = waiting_.find(stamp);
  if (w != waiting_.end()) {
    for (const auto& [t, d] : w->second) run(t, stamp, known->second, d);
    waiting_.erase(w);
  }
  // Waiting messages older than a numbered stamp will never get a number.
  while (!waiting_.empty() && waiting_.begin()->first < stamp) {
    dropped_ += waiting_.begin()->second.size();
    waiting_.erase(waiting_.begin());
  }
  if (newest_ >= config_.first_frame + kFlushWindow) flush(newest_ - kFlushWindow);
}

void ViperExporterNode::run(const std::string& topic, const ros::Time& stamp, uint64_t frame,
                       const ExportDispatch& dispatch) {
  try {
    const std::string problem = dispatch(*exporter_, frame);
    if (!problem.empty())
      ROS_ERROR_THROTTLE(5, "viper_exporter: %s at stamp %s (frame %lu): %s", topic.c_str(), stampText(stamp).c_str(),
                         static_cast<unsigned long>(frame), problem.c_str());
  } catch (const std::exception& e) {  // a file that cannot be written
    fail(e.what());
  }
}

void ViperExporterNode::fail(const std::string& why) {
  ROS_FATAL("viper_exporter: %s; the export stops%s", why.c_str(),
            own_process_ ? " and the process ends (exit code 2)" : "");
  failed_ = true;
  if (own_process_) ros::requestShutdown();
}

void ViperExporterNode::flush(uint64_t frame) {
  try {
    for (const std::string& n : exporter_->flushUpTo(frame)) ROS_WARN_THROTTLE(5, "viper_exporter: %s", n.c_str());
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

int ViperExporterNode::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_ || !exporter_) return exit_code_;
  finished_ = true;
  subs_.clear();
  dropped_ += [&] {
    size_t n = 0;
    for (const auto& [stamp, messages] : waiting_) n += messages.size();
    return n;
  }();
  waiting_.clear();
  try {
    for (const std::string& n : exporter_->finish()) ROS_WARN("viper_exporter: %s", n.c_str());
  } catch (const std::exception& e) {
    ROS_ERROR("viper_exporter: %s", e.what());
    failed_ = true;
  }
  exit_code_ = failed_ ? 2 : (exporter_->stats().skipped + dropped_ == 0 ? 0 : 1);
  return exit_code_;
}

uint64_t ViperExporterNode::framesNumbered() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frame_of_.size();
}

bool ViperExporterNode::inputsConnected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const ros::Subscriber& s : subs_)
    if (s.getNumPublishers() == 0) return false;
  return !subs_.empty();
}

uint64_t ViperExporterNode::messagesReceived() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return received_;
}

std::string ViperExporterNode::summary() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream out;
  if (!exporter_) return "not started";
  const ViperExportStats& s = exporter_->stats();
  out << frame_of_.size() << " frames: img " << s.img << ", cls " << s.cls << ", inst " << s.inst << ", flow "
      << s.flow << ", flowbw " << s.flowbw << ", bb " << s.bb << ", camera rows " << s.camera_rows << "; skipped "
      << s.skipped << " messages, " << dropped_ << " dropped (stamp never numbered)";
  return out.str();
}

bool ViperExporterNode::onFinish(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const int code = finish();
  res.success = code != 2;
  res.message = summary();
  return true;
}

}  // namespace viper
