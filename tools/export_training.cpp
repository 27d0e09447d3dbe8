// export_training: writes a recorded ground-truth bag in the formats training frameworks read
// (Cityscapes gtFine, COCO instance JSON, KITTI flow and depth PNGs) through
// viper::dataset::TrainingExport. A frame is the messages of one header stamp; frames are numbered
// in the order of the stamps of the reference topic (the semantic topic by default). A bad message
// is reported (topic, stamp, what is wrong) and skipped. Exit code: 0 = every message exported,
// 1 = some skipped, 2 = usage, bag or write error. docs/training_formats.md.
#include "command_line.h"
#include "viper/dataset/training_export.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper_progress.h"

#include <ros/package.h>
#include <sensor_msgs/Image.h>

#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Options {
  std::string bag;
  viper::dataset::TrainingExportOptions out;
  std::string formats = "cityscapes,coco,kitti";
  std::string class_table;
  std::string frames_from;
  std::map<std::string, std::string> topics = {{"color", "/capture/color/image_raw"},
                                               {"semantic", "/ground_truth/semantic"},
                                               {"instance_ids", "/ground_truth/instance_ids"},
                                               {"flow", "/ground_truth/flow/forward"},
                                               {"depth", "/capture/depth/image_raw"}};
};

// One frame's parts as they arrive.
struct Parts {
  std::optional<viper::dataset::Image8> rgb, classes;
  std::optional<std::vector<int32_t>> instances;
  std::optional<viper::dataset::FlowImage> flow;
  std::optional<std::vector<float>> depth;
  uint32_t width = 0, height = 0;
  size_t count = 0;
};

std::string stampText(const ros::Time& t) {
  char s[32];
  std::snprintf(s, sizeof s, "%u.%09u", t.sec, t.nsec);
  return s;
}

// Reads one message of `role` into `parts`; returns what is wrong, or "".
std::string take(const std::string& role, const sensor_msgs::Image& m, Parts& parts) {
  std::string problem;
  if (role == "color") {
    parts.rgb.emplace();
    problem = viper::imageFromMsg(m, "rgb8", *parts.rgb);
  } else if (role == "semantic") {
    parts.classes.emplace();
    problem = viper::imageFromMsg(m, "mono8", *parts.classes);
  } else if (role == "instance_ids") {
    parts.instances.emplace();
    problem = viper::int32FromMsg(m, *parts.instances);
  } else if (role == "flow") {
    parts.flow.emplace();
    problem = viper::flowFromMsg(m, *parts.flow);
  } else if (role == "depth") {
    parts.depth.emplace();
    problem = viper::float32FromMsg(m, *parts.depth);
  }
  if (problem.empty() && role != "color" && role != "flow") {
    if (parts.width != 0 && (parts.width != m.width || parts.height != m.height))
      problem = std::to_string(m.width) + "x" + std::to_string(m.height) + " px, the frame's other images " +
                std::to_string(parts.width) + "x" + std::to_string(parts.height) + " px";
    parts.width = m.width;
    parts.height = m.height;
  }
  return problem;
}

int exportBag(Options& o) {
  std::map<std::string, std::string> role_of;  // topic -> role, for the topics the bag has
  std::string reference = o.frames_from;
  try {
    const viper::BagReader bag(o.bag);
    std::set<std::string> topics;
    for (const auto* c : bag.bagConnections()) topics.insert(c->topic);
    for (const auto& [role, topic] : o.topics)
      if (!topic.empty() && topics.count(topic)) role_of[topic] = role;
    if (reference.empty())
      for (const char* r : {"semantic", "instance_ids", "flow", "depth", "color"})
        if (reference.empty() && role_of.count(o.topics[r])) reference = o.topics[r];
  } catch (const viper::BagReadError& e) {
    std::cerr << "export_training: cannot open bag " << o.bag << ": " << e.problem() << "\n";
    return 2;
  }
  if (role_of.empty() || reference.empty()) {
    std::cerr << "export_training: " << o.bag << " has none of the topics (--topic ROLE=TOPIC)\n";
    return 2;
  }
  std::map<ros::Time, uint32_t> frame_of;
  {
    std::set<ros::Time> stamps;
    viper::BagReader ref(o.bag, {reference});
    viper::BagReadMessage m;
    while (ref.next(m)) {
      const auto image = m.instantiate<sensor_msgs::Image>();
      if (image) stamps.insert(image->header.stamp);
    }
    for (const ros::Time& t : stamps) frame_of.emplace(t, static_cast<uint32_t>(frame_of.size()));
  }
  if (frame_of.empty()) {
    std::cerr << "export_training: '" << reference << "' in " << o.bag << " has no image messages\n";
    return 2;
  }

  std::unique_ptr<viper::dataset::TrainingExport> exporter;
  try {
    exporter = std::make_unique<viper::dataset::TrainingExport>(o.out);
  } catch (const std::exception& e) {
    std::cerr << "export_training: " << e.what() << "\n";
    return 2;
  }
  std::set<std::string> topics;
  for (const auto& [t, r] : role_of) topics.insert(t);
  std::map<ros::Time, Parts> pending;
  size_t skipped = 0, done = 0;
  viper::BagReader view(o.bag, topics);
  viper_tools::ProgressBar bar("export_training", view.size(), "messages");
  auto note = [&](const std::string& topic, const ros::Time& stamp, const std::string& problem) {
    bar.interrupt();
    std::cerr << "export_training: skipping " << topic << " at stamp " << stampText(stamp) << ": " << problem << "\n";
    ++skipped;
  };
  auto write = [&](const ros::Time& stamp, Parts& p) {
    viper::dataset::TrainingFrame f;
    f.frame = frame_of.at(stamp);
    std::optional<viper::dataset::ImageView8> rgb;
    if (p.rgb) rgb.emplace(*p.rgb);
    f.rgb = rgb ? &*rgb : nullptr;
    f.class_ids = p.classes ? p.classes->data.data() : nullptr;
    f.instance_ids = p.instances ? p.instances->data() : nullptr;
    f.flow = p.flow ? &*p.flow : nullptr;
    f.depth_m = p.depth ? p.depth->data() : nullptr;
    f.width = p.width;
    f.height = p.height;
    exporter->addFrame(f);
  };
  try {
    viper::BagReadMessage m;
    const auto damaged = [&](const viper::BagReadError& e) {
      for (const viper::BagSkippedMessage& s : e.skipped()) note(s.topic(), s.time, "cannot be read: " + e.problem());
    };
    while (view.nextReadingOn(m, damaged)) {
      bar.update(++done);
      sensor_msgs::ImageConstPtr image;
      try {
        image = m.instantiate<sensor_msgs::Image>();
      } catch (const std::exception& e) {
        note(m.topic(), m.time(), std::string("cannot be read: ") + e.what());
        continue;
      }
      if (!image) {
        note(m.topic(), m.time(), "not a sensor_msgs/Image");
        continue;
      }
      const ros::Time stamp = image->header.stamp;
      if (!frame_of.count(stamp)) {
        note(m.topic(), stamp, "its stamp is not among the " + std::to_string(frame_of.size()) + " stamps of " + reference);
        continue;
      }
      Parts& parts = pending[stamp];
      const std::string problem = take(role_of[m.topic()], *image, parts);
      if (!problem.empty()) {
        note(m.topic(), stamp, problem);
        continue;
      }
      if (++parts.count == role_of.size()) {  // every topic's message of this frame has come
        write(stamp, parts);
        pending.erase(stamp);
      }
    }
    for (auto& [stamp, parts] : pending) write(stamp, parts);  // frames some topic left without a message
    exporter->finish();
  } catch (const std::exception& e) {
    bar.interrupt();
    std::cerr << "export_training: " << e.what() << "\n";
    return 2;
  }
  bar.interrupt();
  const auto& s = exporter->stats();
  std::cout << "export_training: " << frame_of.size() << " frames of " << reference << " -> " << o.out.root
            << ": cityscapes " << s.cityscapes_frames << " frames, coco " << s.coco_images << " images "
            << s.coco_annotations << " annotations (" << s.coco_skipped_objects << " objects of other classes), kitti "
            << s.kitti_flow << " flow " << s.kitti_depth << " depth (" << s.kitti_flow_out_of_range << " flow and "
            << s.kitti_depth_out_of_range << " depth values beyond the encoding, written invalid); skipped " << skipped
            << " messages\n";
  return skipped == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app(
      "Writes a recorded ground-truth bag in the formats training frameworks read: Cityscapes gtFine,\n"
      "COCO instance segmentation JSON, KITTI flow and depth PNGs (docs/training_formats.md).\n"
      "Roles and default topics: color=/capture/color/image_raw semantic=/ground_truth/semantic\n"
      "instance_ids=/ground_truth/instance_ids flow=/ground_truth/flow/forward depth=/capture/depth/image_raw",
      "export_training");
  app.formatter(std::make_shared<viper_tools::HelpFormatter>());
  std::vector<std::string> role_topics;
  app.add_option("--bag", o.bag, "a recorded bag of ground truth")->required()->type_name("GT.bag");
  app.add_option("--out", o.out.root, "the root folder")->required()->type_name("DIR");
  app.add_option("--formats", o.formats, "formats to write, comma-separated")->type_name("cityscapes,coco,kitti")
      ->capture_default_str();
  app.add_option("--split", o.out.split, "the split")->capture_default_str();
  app.add_option("--city", o.out.city, "Cityscapes' city name (no '_')")->capture_default_str();
  app.add_option("--seq", o.out.sequence, "the sequence number, 0..999999")->capture_default_str();
  app.add_option("--frames-from", o.frames_from, "the topic whose stamps number the frames (default: semantic's)");
  app.add_option("--class-table", o.class_table,
                 "the class table (COCO's categories: its classes with instance_eval 1); default the package's")
      ->type_name("CSV");
  app.add_option("--png-level", o.out.images.png_compression_level, "PNG compression, 0..9")->capture_default_str();
  app.add_option("--topic", role_topics, "a role's topic, ROLE=TOPIC (ROLE= turns it off); may be given again");
  app.footer("Exit status: 0 all exported; 1 bad messages skipped (the rest exported); 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;

  for (const std::string& v : role_topics) {
    const size_t eq = v.find('=');
    if (eq == std::string::npos || !o.topics.count(v.substr(0, eq)))
      return viper_tools::usageError(app, "--topic takes ROLE=TOPIC with a role of color, semantic, instance_ids, "
                                          "flow, depth (got '" + v + "')");
    o.topics[v.substr(0, eq)] = v.substr(eq + 1);
  }
  o.out.cityscapes = o.out.coco = o.out.kitti = false;
  std::istringstream formats(o.formats);
  for (std::string f; std::getline(formats, f, ',');) {
    if (f == "cityscapes") o.out.cityscapes = true;
    else if (f == "coco") o.out.coco = true;
    else if (f == "kitti") o.out.kitti = true;
    else return viper_tools::usageError(app, "--formats takes cityscapes, coco, kitti (got '" + f + "')");
  }
  if (o.out.images.png_compression_level < 0 || o.out.images.png_compression_level > 9)
    return viper_tools::usageError(app, "--png-level must be 0..9");
  std::string path = o.class_table;
  if (path.empty()) {
    const std::string share = ros::package::getPath("viper");
    path = (share.empty() ? std::string(VIPER_SOURCE_DIR) : share) + "/config/viper_classes.csv";
  }
  try {
    // The table held while its classes are read (a temporary's classes() would dangle in the loop).
    const viper::ClassTable table = viper::ClassTable::load(path);
    for (const viper::ClassInfo& c : table.classes())
      if (c.instance_eval) o.out.categories.push_back({c.id, c.name, "viper"});
  } catch (const std::exception& e) {
    std::cerr << "export_training: " << e.what() << " (--class-table)\n";
    return 2;
  }
  return exportBag(o);
}
