// export_viper: writes ground truth into VIPER's release layout, from a bag (rosbag C++ API) or from
// live topics (--live, a ROS node): img, cls, inst, flow, flowbw, bb and the camera file. Frame
// numbers follow the header stamps of a reference topic (the camera image by default). Bad messages
// are reported (topic, stamp, what is wrong) and skipped; the rest is exported. Exit code: 0 =
// everything exported, 1 = some messages skipped, 2 = usage error, unreadable bag, or a file that
// cannot be written. docs/viper_layout.md has the details.
#include "viper/ground_truth/class_table.h"
#include "viper/dataset/viper_layout.h"
#include "viper/ros/dataset/viper_exporter.h"
#include "viper_progress.h"

#include <ros/package.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

namespace {

using viper::ViperExporter;

// Each kind of input, its default topic and its message type.
struct Role {
  std::string name, topic, datatype;
};
std::vector<Role> defaultRoles() {
  return {{"color", "/capture/color/image_raw", "sensor_msgs/Image"},
          {"semantic", "/ground_truth/semantic", "sensor_msgs/Image"},
          {"instance_ids", "/ground_truth/instance_ids", "sensor_msgs/Image"},
          {"instances_viper", "/ground_truth/instances_viper", "sensor_msgs/Image"},
          {"flow", "/ground_truth/flow/forward", "sensor_msgs/Image"},
          {"flowbw", "/ground_truth/flow/backward", "sensor_msgs/Image"},
          {"boxes", "/ground_truth/boxes_optical", "viper/Box3DArray"},
          {"objects", "/ground_truth/objects", "viper/ObjectArray"},
          {"draws", "/capture/draws", "viper/DrawList"},
          {"odom", "/ground_truth/odom", "nav_msgs/Odometry"},
          {"camera_info", "/capture/color/camera_info", "sensor_msgs/CameraInfo"}};
}

struct Options {
  std::string bag;
  bool live = false;
  viper::ViperExportOptions exporter;
  std::vector<Role> roles = defaultRoles();
  std::string frames_from;  // "" = the color topic if present, else semantic, else the first image topic
  std::string camera = "auto";
  std::string cls_palette = "viper";
  std::string class_table;
  uint64_t first_frame = 0;
};

const char* kUsage =
    "usage: export_viper --bag GT.bag --out DIR [options]     (a recorded bag)\n"
    "       export_viper --live --out DIR [options]           (live topics, until Ctrl-C)\n"
    "options: [--split train] [--seq 001] [--first-frame 0] [--frames-from TOPIC]\n"
    "         [--img-format png|jpg] [--jpeg-quality 95] [--png-level 1] [--deflate-level 1]\n"
    "         [--cls-palette viper|gray] [--class-table CSV] [--camera auto|draws|odom|none]\n"
    "         [--absolute-poses] [--near 0.1] [--far 1000] [--topic ROLE=TOPIC ...]\n"
    "Roles and default topics (ROLE= with no topic turns a role off):\n"
    "  color=/capture/color/image_raw -> img     semantic=/ground_truth/semantic -> cls\n"
    "  instance_ids=/ground_truth/instance_ids + semantic, or instances_viper=/ground_truth/instances_viper -> inst\n"
    "  flow=/ground_truth/flow/forward -> flow   flowbw=/ground_truth/flow/backward -> flowbw\n"
    "  boxes=/ground_truth/boxes_optical + objects=/ground_truth/objects (2D boxes) -> bb\n"
    "  draws=/capture/draws, or odom=/ground_truth/odom + camera_info=/capture/color/camera_info -> camera\n"
    "Frame n is the n-th header stamp of --frames-from (default: the color topic), plus --first-frame.\n"
    "Exit code: 0 all exported, 1 bad messages skipped (the rest exported), 2 error.\n";

Role* findRole(std::vector<Role>& roles, const std::string& name) {
  for (Role& r : roles)
    if (r.name == name) return &r;
  return nullptr;
}

bool parseArgs(int argc, char** argv, Options& o, std::string& error) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (arg == "--live") {
      o.live = true;
      continue;
    }
    if (arg == "--absolute-poses") {
      o.exporter.relative_poses = false;
      continue;
    }
    if (i + 1 >= argc) {
      error = "missing value after " + arg;
      return false;
    }
    const std::string v = argv[++i];
    try {
      if (arg == "--bag") o.bag = v;
      else if (arg == "--out") o.exporter.root = v;
      else if (arg == "--split") o.exporter.split = v;
      else if (arg == "--seq") o.exporter.seq = v;
      else if (arg == "--first-frame") o.first_frame = std::stoull(v);
      else if (arg == "--frames-from") o.frames_from = v;
      else if (arg == "--img-format") o.exporter.image_extension = v;
      else if (arg == "--jpeg-quality") o.exporter.images.jpeg_quality = std::stoi(v);
      else if (arg == "--png-level") o.exporter.images.png_compression_level = std::stoi(v);
      else if (arg == "--deflate-level") o.exporter.zip.deflate_level = std::stoi(v);
      else if (arg == "--cls-palette") o.cls_palette = v;
      else if (arg == "--class-table") o.class_table = v;
      else if (arg == "--camera") o.camera = v;
      else if (arg == "--near") o.exporter.near_m = std::stod(v);
      else if (arg == "--far") o.exporter.far_m = std::stod(v);
      else if (arg == "--topic") {
        const size_t eq = v.find('=');
        Role* role = eq == std::string::npos ? nullptr : findRole(o.roles, v.substr(0, eq));
        if (role == nullptr) {
          error = "--topic takes ROLE=TOPIC with a role of: color, semantic, instance_ids, instances_viper, flow, "
                  "flowbw, boxes, objects, draws, odom, camera_info (got '" + v + "')";
          return false;
        }
        role->topic = v.substr(eq + 1);
      } else {
        error = "unknown option " + arg;
        return false;
      }
    } catch (const std::exception&) {
      error = "bad number '" + v + "' for " + arg;
      return false;
    }
  }
  if (o.exporter.root.empty()) error = "--out is required";
  else if (o.live == !o.bag.empty()) error = "give either --bag or --live";
  else if (o.exporter.image_extension != "png" && o.exporter.image_extension != "jpg") error = "--img-format must be png or jpg";
  else if (o.exporter.images.jpeg_quality < 0 || o.exporter.images.jpeg_quality > 100) error = "--jpeg-quality must be 0..100";
  else if (o.exporter.images.png_compression_level < 0 || o.exporter.images.png_compression_level > 9) error = "--png-level must be 0..9";
  else if (o.exporter.zip.deflate_level < 0 || o.exporter.zip.deflate_level > 9) error = "--deflate-level must be 0..9";
  else if (o.cls_palette != "viper" && o.cls_palette != "gray") error = "--cls-palette must be viper or gray";
  else if (o.camera != "auto" && o.camera != "draws" && o.camera != "odom" && o.camera != "none")
    error = "--camera must be auto, draws, odom or none";
  else if (!(o.exporter.near_m > 0 && o.exporter.far_m > o.exporter.near_m)) error = "--near and --far need 0 < near < far";
  return error.empty();
}

std::string stampText(const ros::Time& t) {
  char s[32];
  std::snprintf(s, sizeof s, "%u.%09u", t.sec, t.nsec);
  return s;
}

const Role& role(const Options& o, const std::string& name) {
  for (const Role& r : o.roles)
    if (r.name == name) return r;
  throw std::logic_error("no role " + name);
}

// Hands one message of a role to the exporter; returns what is wrong, or "".
using Dispatch = std::function<std::string(ViperExporter&, uint64_t frame)>;

template <typename M>
ros::Time headerStamp(const M& m) {
  return m.header.stamp;
}

// The exporter call for a message of `role_name` (typed), as a Dispatch.
template <typename M>
Dispatch dispatchFor(const std::string& role_name, const boost::shared_ptr<const M>& m);

template <>
Dispatch dispatchFor<sensor_msgs::Image>(const std::string& r, const sensor_msgs::ImageConstPtr& m) {
  if (r == "color") return [m](ViperExporter& e, uint64_t f) { return e.addColor(f, *m); };
  if (r == "semantic") return [m](ViperExporter& e, uint64_t f) { return e.addSemantic(f, m); };
  if (r == "instance_ids") return [m](ViperExporter& e, uint64_t f) { return e.addInstanceIds(f, m); };
  if (r == "instances_viper") return [m](ViperExporter& e, uint64_t f) { return e.addInstancesViper(f, *m); };
  if (r == "flow") return [m](ViperExporter& e, uint64_t f) { return e.addFlow(f, *m, false); };
  return [m](ViperExporter& e, uint64_t f) { return e.addFlow(f, *m, true); };
}
template <>
Dispatch dispatchFor<viper::Box3DArray>(const std::string&, const viper::Box3DArray::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addBoxesOptical(f, m); };
}
template <>
Dispatch dispatchFor<viper::ObjectArray>(const std::string&, const viper::ObjectArray::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addObjects(f, m); };
}
template <>
Dispatch dispatchFor<viper::DrawList>(const std::string&, const viper::DrawList::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addDraws(f, *m); };
}
template <>
Dispatch dispatchFor<nav_msgs::Odometry>(const std::string&, const nav_msgs::Odometry::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addOdometry(f, *m); };
}
template <>
Dispatch dispatchFor<sensor_msgs::CameraInfo>(const std::string&, const sensor_msgs::CameraInfo::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addCameraInfo(f, *m); };
}

// Instantiates a bag message of a role: its stamp and its dispatch.
bool fromBag(const std::string& r, const std::string& datatype, const rosbag::MessageInstance& mi, ros::Time& stamp,
             Dispatch& dispatch) {
  auto take = [&](auto typed) {
    if (!typed) return false;
    using M = std::decay_t<decltype(*typed)>;
    stamp = headerStamp(*typed);
    dispatch = dispatchFor<M>(r, boost::shared_ptr<const M>(typed));
    return true;
  };
  if (datatype == "sensor_msgs/Image") return take(mi.instantiate<sensor_msgs::Image>());
  if (datatype == "viper/Box3DArray") return take(mi.instantiate<viper::Box3DArray>());
  if (datatype == "viper/ObjectArray") return take(mi.instantiate<viper::ObjectArray>());
  if (datatype == "viper/DrawList") return take(mi.instantiate<viper::DrawList>());
  if (datatype == "nav_msgs/Odometry") return take(mi.instantiate<nav_msgs::Odometry>());
  if (datatype == "sensor_msgs/CameraInfo") return take(mi.instantiate<sensor_msgs::CameraInfo>());
  return false;
}

// Live: frames a message may trail behind the newest numbered frame before its frame is completed
// with what it has (a bag is completed at its end: its messages of one frame can be far apart).
constexpr uint64_t kFlushWindow = 30;

int exportBag(Options& o) {
  rosbag::Bag bag;
  try {
    bag.open(o.bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    std::cerr << "export_viper: cannot open bag " << o.bag << ": " << e.what() << "\n";
    return 2;
  }
  std::map<std::string, std::string> types;  // topic -> datatype
  for (const auto* c : rosbag::View(bag).getConnections()) types[c->topic] = c->datatype;
  std::map<std::string, std::string> role_of;  // topic -> role
  for (Role& r : o.roles) {
    if (r.topic.empty() || !types.count(r.topic)) continue;
    if (types[r.topic] != r.datatype) {
      std::cerr << "export_viper: " << r.topic << " (" << r.name << ") in " << o.bag << " carries " << types[r.topic]
                << ", expected " << r.datatype << "\n";
      return 2;
    }
    role_of[r.topic] = r.name;
  }
  if (role_of.empty()) {
    std::cerr << "export_viper: " << o.bag << " has none of the export topics; its topics:";
    for (const auto& [t, d] : types) std::cerr << "\n  " << t << " (" << d << ")";
    std::cerr << "\n";
    return 2;
  }
  if (o.camera == "auto") {
    const bool draws = role_of.count(role(o, "draws").topic) != 0;
    const bool odom = role_of.count(role(o, "odom").topic) && role_of.count(role(o, "camera_info").topic);
    o.camera = draws ? "draws" : odom ? "odom" : "none";
  }
  o.exporter.camera = o.camera == "draws" ? viper::CameraSource::kDraws
                      : o.camera == "odom" ? viper::CameraSource::kOdometry
                                           : viper::CameraSource::kNone;
  auto present = [&](const char* r) { return role_of.count(role(o, r).topic) != 0; };
  o.exporter.inputs.semantic = present("semantic");
  o.exporter.inputs.instance_ids = present("instance_ids");
  o.exporter.inputs.instances_viper = present("instances_viper");
  o.exporter.inputs.objects = present("objects");

  // Frame numbers: the header stamps of the reference topic, in order.
  std::string reference = o.frames_from;
  if (reference.empty())
    for (const char* r : {"color", "semantic", "instance_ids", "instances_viper", "flow"})
      if (reference.empty() && role_of.count(role(o, r).topic)) reference = role(o, r).topic;
  if (!types.count(reference)) {
    std::cerr << "export_viper: " << o.bag << " has no messages on '" << reference << "' (--frames-from)\n";
    return 2;
  }
  std::set<ros::Time> stamps;
  {
    rosbag::View ref(bag, rosbag::TopicQuery(reference));
    for (const rosbag::MessageInstance& m : ref) {
      ros::Time stamp;
      Dispatch ignored;
      const std::string datatype = types[reference];
      if (fromBag("", datatype, m, stamp, ignored)) stamps.insert(stamp);
    }
  }
  if (stamps.empty()) {
    std::cerr << "export_viper: '" << reference << "' in " << o.bag << " has no message with a header stamp\n";
    return 2;
  }
  std::map<ros::Time, uint64_t> frame_of;
  for (const ros::Time& t : stamps) frame_of.emplace(t, o.first_frame + frame_of.size());

  std::unique_ptr<ViperExporter> exporter;
  try {
    exporter = std::make_unique<ViperExporter>(o.exporter);
  } catch (const std::exception& e) {
    std::cerr << "export_viper: " << e.what() << "\n";
    return 2;
  }
  std::vector<std::string> topics;
  for (const auto& [t, r] : role_of) topics.push_back(t);
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  viper_tools::ProgressBar bar("export_viper", view.size(), "messages");
  size_t done = 0, notes = 0;
  auto note = [&](const std::string& text) {
    bar.interrupt();
    std::cerr << "export_viper: " << text << "\n";
    ++notes;
  };
  try {
    for (const rosbag::MessageInstance& m : view) {
      ++done;
      const std::string& r = role_of[m.getTopic()];
      ros::Time stamp = m.getTime();
      Dispatch dispatch;
      std::string problem;
      try {
        if (!fromBag(r, m.getDataType(), m, stamp, dispatch)) problem = "cannot be read as " + m.getDataType();
      } catch (const std::exception& e) {
        problem = std::string("cannot be read: ") + e.what();
      }
      const auto frame = frame_of.find(stamp);
      if (problem.empty() && frame == frame_of.end())
        problem = "its stamp is not among the " + std::to_string(frame_of.size()) + " stamps of " + reference;
      if (problem.empty()) problem = dispatch(*exporter, frame->second);
      if (!problem.empty())
        note("skipping " + m.getTopic() + " at stamp " + stampText(stamp) +
             (frame != frame_of.end() ? " (frame " + std::to_string(frame->second) + ")" : "") + ": " + problem);
      bar.update(done);
    }
    for (const std::string& n : exporter->finish()) note(n);
  } catch (const std::exception& e) {  // a file that cannot be written, or a damaged bag
    bar.interrupt();
    std::cerr << "export_viper: " << e.what() << "\n";
    return 2;
  }
  const viper::ViperExportStats& s = exporter->stats();
  std::cout << "export_viper: " << frame_of.size() << " frames of " << reference << " -> "
            << (std::filesystem::path(o.exporter.root) / o.exporter.split).string() << " sequence " << o.exporter.seq
            << ": img " << s.img << ", cls " << s.cls << ", inst " << s.inst << ", flow " << s.flow << ", flowbw "
            << s.flowbw << ", bb " << s.bb << ", camera rows " << s.camera_rows << " (" << o.camera << "); skipped "
            << s.skipped << " messages\n";
  return s.skipped == 0 ? 0 : 1;
}

// Live topics: the node's subscribers feed the exporter; frame numbers are given in the order the
// reference topic's stamps arrive, and messages of a stamp not seen yet wait for it.
class LiveExport {
 public:
  LiveExport(ros::NodeHandle nh, Options& o) : nh_(nh), o_(o) {}

  bool start() {
    if (o_.camera == "auto") o_.camera = "draws";
    o_.exporter.camera = o_.camera == "draws" ? viper::CameraSource::kDraws
                         : o_.camera == "odom" ? viper::CameraSource::kOdometry
                                               : viper::CameraSource::kNone;
    reference_ = o_.frames_from.empty() ? role(o_, "color").topic : o_.frames_from;
    auto on = [&](const char* r) { return !role(o_, r).topic.empty(); };
    o_.exporter.inputs.semantic = on("semantic");
    o_.exporter.inputs.instance_ids = on("instance_ids");
    o_.exporter.inputs.instances_viper = false;  // may never come: semantic + instance ids are paired
    o_.exporter.inputs.objects = on("objects");
    try {
      exporter_ = std::make_unique<ViperExporter>(o_.exporter);
    } catch (const std::exception& e) {
      ROS_FATAL("export_viper: %s", e.what());
      return false;
    }

    for (const Role& r : o_.roles) {
      if (r.topic.empty()) continue;
      if (r.name == "draws" && o_.camera != "draws") continue;
      if ((r.name == "odom" || r.name == "camera_info") && o_.camera != "odom") continue;
      if (r.datatype == "sensor_msgs/Image") subscribe<sensor_msgs::Image>(r);
      else if (r.datatype == "viper/Box3DArray") subscribe<viper::Box3DArray>(r);
      else if (r.datatype == "viper/ObjectArray") subscribe<viper::ObjectArray>(r);
      else if (r.datatype == "viper/DrawList") subscribe<viper::DrawList>(r);
      else if (r.datatype == "nav_msgs/Odometry") subscribe<nav_msgs::Odometry>(r);
      else if (r.datatype == "sensor_msgs/CameraInfo") subscribe<sensor_msgs::CameraInfo>(r);
    }
    ROS_INFO("export_viper: writing %s/%s sequence %s; frames numbered by %s", o_.exporter.root.c_str(),
             o_.exporter.split.c_str(), o_.exporter.seq.c_str(), reference_.c_str());
    return true;
  }

  int finish() {
    try {
      for (const std::string& n : exporter_->finish()) ROS_WARN("export_viper: %s", n.c_str());
    } catch (const std::exception& e) {
      ROS_ERROR("export_viper: %s", e.what());
      return 2;
    }
    const viper::ViperExportStats& s = exporter_->stats();
    std::cout << "export_viper: " << next_frame_ - o_.first_frame << " frames: img " << s.img << ", cls " << s.cls
              << ", inst " << s.inst << ", flow " << s.flow << ", flowbw " << s.flowbw << ", bb " << s.bb
              << ", camera rows " << s.camera_rows << "; skipped " << s.skipped << " messages, " << dropped_
              << " dropped (stamp never numbered)\n";
    return failed_ ? 2 : (s.skipped + dropped_ == 0 ? 0 : 1);
  }

 private:
  template <typename M>
  void subscribe(const Role& r) {
    const std::string topic = r.topic, name = r.name;
    subs_.push_back(nh_.subscribe<M>(topic, 100, [this, topic, name](const boost::shared_ptr<const M>& m) {
      onMessage(topic, m->header.stamp, dispatchFor<M>(name, m));
    }));
  }

  void onMessage(const std::string& topic, const ros::Time& stamp, const Dispatch& dispatch) {
    if (failed_) return;
    auto known = frame_of_.find(stamp);
    if (known == frame_of_.end() && topic == reference_) {
      if (!frame_of_.empty() && stamp < frame_of_.rbegin()->first)
        ROS_WARN_THROTTLE(5, "export_viper: %s stamp %s is older than the newest; numbered after it", topic.c_str(),
                          stampText(stamp).c_str());
      known = frame_of_.emplace(stamp, next_frame_++).first;
      newest_ = known->second;
    }
    if (known == frame_of_.end()) {
      if (!frame_of_.empty() && stamp < frame_of_.rbegin()->first) {
        ++dropped_;
        ROS_ERROR_THROTTLE(5, "export_viper: dropping %s at stamp %s: %s never had that stamp", topic.c_str(),
                           stampText(stamp).c_str(), reference_.c_str());
        return;
      }
      waiting_[stamp].emplace_back(topic, dispatch);
      while (waiting_.size() > kMaxWaitingStamps) {
        dropped_ += waiting_.begin()->second.size();
        ROS_ERROR_THROTTLE(5, "export_viper: dropping messages at stamp %s: %s has not published that stamp",
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
    if (newest_ >= o_.first_frame + kFlushWindow) flush(newest_ - kFlushWindow);
  }

  void run(const std::string& topic, const ros::Time& stamp, uint64_t frame, const Dispatch& dispatch) {
    try {
      const std::string problem = dispatch(*exporter_, frame);
      if (!problem.empty())
        ROS_ERROR_THROTTLE(5, "export_viper: %s at stamp %s (frame %lu): %s", topic.c_str(), stampText(stamp).c_str(),
                           static_cast<unsigned long>(frame), problem.c_str());
    } catch (const std::exception& e) {
      ROS_FATAL("export_viper: %s; stopping", e.what());
      failed_ = true;
      ros::shutdown();
    }
  }

  void flush(uint64_t frame) {
    try {
      for (const std::string& n : exporter_->flushUpTo(frame)) ROS_WARN_THROTTLE(5, "export_viper: %s", n.c_str());
    } catch (const std::exception& e) {
      ROS_FATAL("export_viper: %s; stopping", e.what());
      failed_ = true;
      ros::shutdown();
    }
  }

  static constexpr size_t kMaxWaitingStamps = 64;
  ros::NodeHandle nh_;
  Options& o_;
  std::unique_ptr<ViperExporter> exporter_;
  std::string reference_;
  std::vector<ros::Subscriber> subs_;
  std::map<ros::Time, uint64_t> frame_of_;
  std::map<ros::Time, std::vector<std::pair<std::string, Dispatch>>> waiting_;
  uint64_t next_frame_ = 0, newest_ = 0;
  size_t dropped_ = 0;
  bool failed_ = false;

 public:
  void setFirstFrame(uint64_t f) { next_frame_ = f; }
};

}  // namespace

int main(int argc, char** argv) {
  // Live: ROS takes its own arguments (name:=value remappings) out of argv first.
  if (std::any_of(argv + 1, argv + argc, [](const char* a) { return std::string(a) == "--live"; }))
    ros::init(argc, argv, "export_viper");
  Options o;
  std::string error;
  if (!parseArgs(argc, argv, o, error)) {
    std::cerr << "export_viper: " << error << "\n" << kUsage;
    return 2;
  }
  try {
    viper::dataset::viperFramePath(o.exporter.root, o.exporter.split, "img", o.exporter.seq, 0, "png");
  } catch (const std::invalid_argument& e) {
    std::cerr << "export_viper: " << e.what() << "\n";
    return 2;
  }
  if (o.cls_palette == "viper") {
    std::string path = o.class_table;
    if (path.empty()) {
      const std::string share = ros::package::getPath("viper");
      path = (share.empty() ? std::string(VIPER_SOURCE_DIR) : share) + "/config/viper_classes.csv";
    }
    try {
      const viper::ClassTable table = viper::ClassTable::load(path);
      for (const viper::ClassInfo& c : table.classes()) o.exporter.palette.push_back(c.rgb);
    } catch (const std::exception& e) {
      std::cerr << "export_viper: " << e.what() << " (--class-table)\n";
      return 2;
    }
  }
  if (!o.live) {
    try {
      return exportBag(o);
    } catch (const std::exception& e) {
      std::cerr << "\nexport_viper: " << o.bag << ": " << e.what() << "\n";
      return 2;
    }
  }
  ros::NodeHandle nh;
  LiveExport live(nh, o);
  live.setFirstFrame(o.first_frame);
  if (!live.start()) return 2;
  ros::spin();
  return live.finish();
}
