// export_viper: writes ground truth into VIPER's release layout, from a bag (viper::BagReader) or from
// live topics (--live, a ROS node): img, cls, inst, flow, flowbw, bb and the camera file. Frame
// numbers follow the header stamps of a reference topic (the camera image by default). Bad messages
// are reported (topic, stamp, what is wrong) and skipped; the rest is exported. Exit code: 0 =
// everything exported, 1 = some messages skipped, 2 = usage error, unreadable bag, or a file that
// cannot be written. docs/viper_layout.md has the details.
#include "command_line.h"
#include "viper/ground_truth/class_table.h"
#include "viper/dataset/viper_layout.h"
#include "viper/ros/dataset/export_roles.h"
#include "viper/ros/dataset/viper_exporter.h"
#include "viper/ros/dataset/viper_exporter_node.h"
#include "viper_progress.h"

#include <ros/package.h>
#include <ros/ros.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

namespace {

using viper::ExportDispatch;
using viper::ExportRole;
using viper::ViperExporter;
using viper::stampText;

struct Options {
  std::string bag;
  bool live = false;
  viper::ViperExportOptions exporter;
  std::vector<ExportRole> roles = viper::defaultExportRoles();
  std::string frames_from;  // "" = the color topic if present, else semantic, else the first image topic
  std::string camera = "auto";
  std::string cls_palette = "viper";
  std::string class_table;
  uint64_t first_frame = 0;
};

// The topics of --topic ROLE=TOPIC (ROLE= turns a role off), given in order; the error, empty if none.
std::string setTopics(const std::vector<std::string>& role_topics, Options& o) {
  for (const std::string& v : role_topics) {
    const size_t eq = v.find('=');
    ExportRole* role = eq == std::string::npos ? nullptr : viper::findExportRole(o.roles, v.substr(0, eq));
    if (role == nullptr)
      return "--topic takes ROLE=TOPIC with a role of: color, semantic, instance_ids, instances_viper, flow, "
             "flowbw, boxes, objects, draws, odom, camera_info (got '" + v + "')";
    role->topic = v.substr(eq + 1);
  }
  return "";
}

const ExportRole& role(const Options& o, const std::string& name) { return viper::exportRole(o.roles, name); }

int exportBag(Options& o) {
  std::map<std::string, std::string> types;  // topic -> datatype
  try {
    const viper::BagReader bag(o.bag);
    for (const auto* c : bag.bagConnections()) types[c->topic] = c->field("type");
  } catch (const viper::BagReadError& e) {
    std::cerr << "export_viper: cannot open bag " << o.bag << ": " << e.problem() << "\n";
    return 2;
  }
  std::map<std::string, std::string> role_of;  // topic -> role
  for (ExportRole& r : o.roles) {
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
  o.exporter.camera = viper::cameraSourceOf(o.camera);
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
    viper::BagReader ref(o.bag, {reference});
    viper::BagReadMessage m;
    while (ref.next(m)) {
      ros::Time stamp;
      ExportDispatch ignored;
      const std::string datatype = types[reference];
      if (viper::exportDispatchFromBag("", datatype, m, stamp, ignored)) stamps.insert(stamp);
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
  std::set<std::string> topics;
  for (const auto& [t, r] : role_of) topics.insert(t);
  viper::BagReader view(o.bag, topics);
  viper_tools::ProgressBar bar("export_viper", view.size(), "messages");
  size_t done = 0, notes = 0;
  auto note = [&](const std::string& text) {
    bar.interrupt();
    std::cerr << "export_viper: " << text << "\n";
    ++notes;
  };
  auto skipping = [&](const std::string& topic, const ros::Time& stamp, const std::string& problem) {
    const auto frame = frame_of.find(stamp);
    note("skipping " + topic + " at stamp " + stampText(stamp) +
         (frame != frame_of.end() ? " (frame " + std::to_string(frame->second) + ")" : "") + ": " + problem);
  };
  // A damaged chunk's messages cannot be read: each is noted, as a bad message, and skipped.
  const auto damaged = [&](const viper::BagReadError& e) {
    for (const viper::BagSkippedMessage& s : e.skipped()) {
      ++done;
      skipping(s.topic(), s.time, "cannot be read: " + e.problem());
      bar.update(done);
    }
  };
  try {
    viper::BagReadMessage m;
    while (view.nextReadingOn(m, damaged)) {
      ++done;
      const std::string& r = role_of[m.topic()];
      ros::Time stamp = m.time();
      ExportDispatch dispatch;
      std::string problem;
      try {
        if (!viper::exportDispatchFromBag(r, m.datatype(), m, stamp, dispatch)) problem = "cannot be read as " + m.datatype();
      } catch (const std::exception& e) {
        problem = std::string("cannot be read: ") + e.what();
      }
      const auto frame = frame_of.find(stamp);
      if (problem.empty() && frame == frame_of.end())
        problem = "its stamp is not among the " + std::to_string(frame_of.size()) + " stamps of " + reference;
      if (problem.empty()) problem = dispatch(*exporter, frame->second);
      if (!problem.empty()) skipping(m.topic(), stamp, problem);
      bar.update(done);
    }
    for (const std::string& n : exporter->finish()) note(n);
  } catch (const std::exception& e) {  // a file that cannot be written, or a bag that cannot be read on
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

}  // namespace

int main(int argc, char** argv) {
  // Live: ROS takes its own arguments (name:=value remappings) out of argv first.
  if (std::any_of(argv + 1, argv + argc, [](const char* a) { return std::string(a) == "--live"; }))
    ros::init(argc, argv, "export_viper");
  CLI::App app(
      "Writes ground truth into VIPER's release layout, from a recorded bag (--bag) or from live topics\n"
      "(--live, until Ctrl-C): img, cls, inst, flow, flowbw, bb and the camera file.\n"
      "Roles and default topics (ROLE= with no topic turns a role off):\n"
      "  color=/capture/color/image_raw -> img     semantic=/ground_truth/semantic -> cls\n"
      "  instance_ids=/ground_truth/instance_ids + semantic, or instances_viper=/ground_truth/instances_viper -> inst\n"
      "  flow=/ground_truth/flow/forward -> flow   flowbw=/ground_truth/flow/backward -> flowbw\n"
      "  boxes=/ground_truth/boxes_optical + objects=/ground_truth/objects (2D boxes) -> bb\n"
      "  draws=/capture/draws, or odom=/ground_truth/odom + camera_info=/capture/color/camera_info -> camera\n"
      "Frame n is the n-th header stamp of --frames-from (default: the color topic), plus --first-frame.",
      "export_viper");
  Options o;
  std::vector<std::string> role_topics;
  bool absolute_poses = false;
  app.add_option("--bag", o.bag, "a recorded bag of ground truth")->type_name("GT.bag");
  app.add_flag("--live", o.live, "the live topics instead, until Ctrl-C (a ROS node)");
  app.add_option("--out", o.exporter.root, "the layout's root")->required()->type_name("DIR");
  app.add_option("--split", o.exporter.split, "the split")->type_name("SPLIT")->capture_default_str();
  app.add_option("--seq", o.exporter.seq, "the sequence")->type_name("SEQ")->capture_default_str();
  app.add_option("--first-frame", o.first_frame, "the number of the first frame")->capture_default_str();
  app.add_option("--frames-from", o.frames_from,
                 "number the frames by the header stamps of this topic (default: the color topic if present, "
                 "else semantic, else the first image topic)")
      ->type_name("TOPIC");
  app.add_option("--img-format", o.exporter.image_extension, "img files")->type_name("png|jpg")->capture_default_str();
  app.add_option("--jpeg-quality", o.exporter.images.jpeg_quality, "0..100")->capture_default_str();
  app.add_option("--png-level", o.exporter.images.png_compression_level, "PNG compression, 0..9")
      ->capture_default_str();
  app.add_option("--deflate-level", o.exporter.zip.deflate_level, "npz compression, 0..9")->capture_default_str();
  app.add_option("--cls-palette", o.cls_palette, "cls files: the class table's colors, or gray levels")
      ->type_name("viper|gray")
      ->capture_default_str();
  app.add_option("--class-table", o.class_table,
                 "the classes' colors (default: the package's config/viper_classes.csv)")
      ->type_name("CSV");
  app.add_option("--camera", o.camera,
                 "the camera file from the draws, from odometry and camera info, or none (auto: draws if "
                 "present, else odom)")
      ->type_name("auto|draws|odom|none")
      ->capture_default_str();
  app.add_flag("--absolute-poses", absolute_poses,
               "view matrices as they are (default: relative to the first exported frame, as VIPER)");
  app.add_option("--near", o.exporter.near_m, "with --camera odom, the depth range of the projection written, m")
      ->capture_default_str();
  app.add_option("--far", o.exporter.far_m, "with --camera odom, the depth range of the projection written, m")
      ->capture_default_str();
  app.add_option("--topic", role_topics, "a role's topic (ROLE= turns it off); may be given again")
      ->type_name("ROLE=TOPIC");
  app.footer("Exit status: 0 all exported; 1 bad messages skipped (the rest exported); 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  o.exporter.relative_poses = !absolute_poses;
  std::string error = setTopics(role_topics, o);
  if (error.empty() && o.live == !o.bag.empty()) error = "give either --bag or --live";
  if (error.empty()) error = viper::exportOptionsProblem(o.exporter, o.cls_palette, o.camera);
  if (!error.empty()) return viper_tools::usageError(app, error);
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
      o.exporter.palette = viper::classPalette(path);
    } catch (const std::exception& e) {
      std::cerr << "export_viper: " << e.what() << " (--class-table)\n";
      return 2;
    }
  }
  if (!o.live) {
    try {
      return exportBag(o);
    } catch (const viper::BagReadError& e) {  // a damaged bag (what() names it)
      std::cerr << "\nexport_viper: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "\nexport_viper: " << o.bag << ": " << e.what() << "\n";
      return 2;
    }
  }
  // Live: the viper_exporter node's class with this command line's settings.
  viper::LiveExportConfig config;
  config.exporter = o.exporter;
  config.roles = o.roles;
  config.frames_from = o.frames_from;
  config.camera = o.camera;
  config.first_frame = o.first_frame;
  viper::ViperExporterNode live(ros::NodeHandle(), config);
  if (!live.start()) return 2;
  ros::spin();
  const int code = live.finish();
  std::cout << "export_viper: " << live.summary() << "\n";
  return code;
}
