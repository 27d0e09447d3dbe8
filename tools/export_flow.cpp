// export_flow: writes the 32FC2 flow images of one bag topic as files of VIPER's release layout,
// <out>/<split>/<modality>/<seq>/<seq>_<frame>.npz, and/or Middlebury .flo files beside them.
// Frame numbers count the topic's messages in bag order from --first-frame, or, with --frames-from,
// are the position of the flow's header stamp among the stamps of another topic (the images). A
// bad message is reported (topic, stamp, what is wrong), skipped, and keeps its number. Exit
// code: 0 = every message exported, 1 = some skipped, the rest exported, 2 = usage, bag or write
// error. docs/dataset_io.md has the details.
#include "command_line.h"
#include "viper/dataset/middlebury_flo.h"
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"
#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/conversions/flow_conversions.h"

#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using viper::dataset::FlowImage;

struct Options {
  std::string bag, out;
  std::string topic = "/ground_truth/flow/forward";
  std::string frames_from;
  std::string format = "npz";
  std::string seq = "001";
  std::string split = "train";
  std::string modality = "flow";
  uint64_t first_frame = 0;
  int deflate_level = viper::dataset::ZipWriteOptions().deflate_level;
};

std::string stampText(const ros::Time& t) {
  char s[32];
  std::snprintf(s, sizeof s, "%u.%09u", t.sec, t.nsec);
  return s;
}

// The header stamps of the messages of `topic`, in bag order, each mapped to its index. The
// header is read from the serialized bytes, so any message type that starts with one will do.
bool frameStamps(const std::string& path, const std::string& topic, std::map<ros::Time, uint64_t>& frames,
                 std::string& error) {
  viper::BagReader view(path, {topic});
  if (view.size() == 0) {
    error = "has no messages on " + topic;
    return false;
  }
  for (const auto* c : view.connections()) {
    std::istringstream def(c->field("message_definition"));
    std::string line;
    while (std::getline(def, line) && (line.empty() || line[0] == '#')) {
    }
    if (line.rfind("Header header", 0) != 0 && line.rfind("std_msgs/Header header", 0) != 0) {
      error = "carries " + c->field("type") + " on " + topic + ", which has no header stamp";
      return false;
    }
  }
  uint64_t index = 0;
  viper::BagReadMessage m;
  while (view.next(m)) {
    ros::serialization::IStream in(const_cast<uint8_t*>(m.data()), m.size());
    uint32_t seq = 0;
    ros::Time stamp;
    ros::serialization::deserialize(in, seq);
    ros::serialization::deserialize(in, stamp);
    frames.emplace(stamp, index++);  // a repeated stamp keeps its first index
  }
  return true;
}

class Progress {
 public:
  explicit Progress(size_t total) : total_(total), tty_(isatty(STDERR_FILENO) != 0) {}
  void update(size_t done, size_t skipped) {
    const size_t every = total_ >= 10 ? total_ / 10 : 1;
    if (!tty_ && done % every != 0 && done != total_) return;
    std::fprintf(stderr, "%sexport_flow: %zu/%zu messages (%zu skipped)%s", tty_ ? "\r" : "", done, total_,
                 skipped, tty_ ? "" : "\n");
    if (tty_ && done == total_) std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  // A message of its own must start on a fresh line.
  void interrupt() {
    if (tty_) std::fputc('\n', stderr);
  }

 private:
  size_t total_;
  bool tty_;
};

int run(const Options& o) {
  std::unique_ptr<viper::BagReader> bag;
  try {
    bag = std::make_unique<viper::BagReader>(o.bag, std::set<std::string>{o.topic});
  } catch (const viper::BagReadError& e) {
    std::cerr << "export_flow: cannot open bag " << o.bag << ": " << e.problem() << "\n";
    return 2;
  }
  viper::BagReader& view = *bag;
  if (view.size() == 0) {
    std::set<std::string> topics;
    for (const auto* c : view.bagConnections()) topics.insert(c->topic + " (" + c->field("type") + ")");
    std::cerr << "export_flow: " << o.bag << " has no messages on " << o.topic << "; its topics:";
    for (const auto& t : topics) std::cerr << "\n  " << t;
    std::cerr << "\n";
    return 2;
  }
  for (const auto* c : view.connections())
    if (c->field("type") != "sensor_msgs/Image") {
      std::cerr << "export_flow: " << o.topic << " in " << o.bag << " carries " << c->field("type")
                << ", expected sensor_msgs/Image (32FC2)\n";
      return 2;
    }

  std::map<ros::Time, uint64_t> frames;
  if (!o.frames_from.empty()) {
    std::string error;
    if (!frameStamps(o.bag, o.frames_from, frames, error)) {
      std::cerr << "export_flow: " << o.bag << " " << error << " (--frames-from)\n";
      return 2;
    }
  }

  const bool npz = o.format != "flo", flo = o.format != "npz";
  viper::dataset::ZipWriteOptions zip;
  zip.deflate_level = o.deflate_level;
  const std::string dir =
      std::filesystem::path(viper::dataset::viperFramePath(o.out, o.split, o.modality, o.seq, 0, "npz"))
          .parent_path()
          .string();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::cerr << "export_flow: cannot create " << dir << ": " << ec.message() << "\n";
    return 2;
  }

  Progress progress(view.size());
  size_t index = 0, written = 0, skipped = 0;
  // The message's frame: its index, or its stamp's among --frames-from's (false: not among them).
  auto frameOf = [&](uint64_t message, const ros::Time& stamp, uint64_t& frame) {
    frame = o.first_frame + message;
    if (frames.empty()) return true;
    const auto f = frames.find(stamp);
    if (f == frames.end()) return false;
    frame = o.first_frame + f->second;
    return true;
  };
  auto skip = [&](uint64_t message, const ros::Time& stamp, const std::string& problem) {
    uint64_t frame = 0;
    const bool frame_known = frameOf(message, stamp, frame);
    ++skipped;
    progress.interrupt();
    std::cerr << "export_flow: skipping " << o.topic << " at stamp " << stampText(stamp) << " ("
              << (frame_known ? "frame " + std::to_string(frame) : "message " + std::to_string(message))
              << "): " << problem << "\n";
    progress.update(index, skipped);
  };
  // A damaged chunk's messages cannot be read: each is skipped, as a bad message, and keeps its number.
  const auto damaged = [&](const viper::BagReadError& e) {
    for (const viper::BagSkippedMessage& s : e.skipped()) {
      const uint64_t message = index++;
      skip(message, s.time, "cannot be read: " + e.problem());
    }
  };
  FlowImage flow;
  viper::BagReadMessage m;
  while (view.nextReadingOn(m, damaged)) {
    const uint64_t message = index++;
    std::string problem;
    ros::Time stamp = m.time();
    try {
      const sensor_msgs::Image::ConstPtr image = m.instantiate<sensor_msgs::Image>();
      if (image == nullptr) problem = "not a sensor_msgs/Image";
      else {
        stamp = image->header.stamp;
        problem = viper::flowFromMsg(*image, flow);
      }
    } catch (const std::exception& e) {
      problem = std::string("cannot be read: ") + e.what();
    }
    uint64_t frame = 0;
    if (!frameOf(message, stamp, frame) && problem.empty())
      problem = "its stamp is not among the " + std::to_string(frames.size()) + " stamps of " + o.frames_from;
    if (!problem.empty()) {
      skip(message, stamp, problem);
      continue;
    }
    try {
      if (npz) {
        const auto path = viper::dataset::viperFramePath(o.out, o.split, o.modality, o.seq, frame, "npz");
        const auto stats = viper::dataset::writeViperFlow(path, flow, zip);
        if (stats.overflowed > 0) {
          progress.interrupt();
          std::cerr << "export_flow: " << o.topic << " at stamp " << stampText(stamp) << ": " << stats.overflowed
                    << " flow values of 65520 px or more became inf (invalid) in float16\n";
        }
      }
      if (flo)
        viper::dataset::writeMiddleburyFlo(
            viper::dataset::viperFramePath(o.out, o.split, o.modality, o.seq, frame, "flo"), flow);
    } catch (const std::exception& e) {
      progress.interrupt();
      std::cerr << "export_flow: " << e.what() << "\n";
      return 2;
    }
    ++written;
    progress.update(index, skipped);
  }
  std::cout << "export_flow: wrote " << written << " of " << index << " messages of " << o.topic << " to " << dir
            << " (" << o.format << "), skipped " << skipped << "\n";
  return skipped == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Writes every sensor_msgs/Image (32FC2) of TOPIC to DIR/SPLIT/MODALITY/SEQ/SEQ_FRAME.npz (VIPER) and/or\n"
      ".flo (Middlebury). FRAME (5 digits) = first-frame + index of the message on the topic, or with\n"
      "--frames-from (e.g. /capture/color/image_raw) first-frame + index of the flow's stamp among that\n"
      "topic's header stamps.",
      "export_flow");
  Options o;
  app.add_option("--bag", o.bag, "the bag to read")->required()->type_name("IN.bag");
  app.add_option("--out", o.out, "the dataset's root")->required()->type_name("DIR");
  app.add_option("--topic", o.topic, "the flow images' topic")->type_name("TOPIC")->capture_default_str();
  app.add_option("--format", o.format, "VIPER's npz, Middlebury's flo, or both")
      ->check(CLI::IsMember({"npz", "flo", "both"}))
      ->capture_default_str();
  app.add_option("--seq", o.seq, "the sequence")->type_name("SEQ")->capture_default_str();
  app.add_option("--split", o.split, "the split")->type_name("SPLIT")->capture_default_str();
  app.add_option("--modality", o.modality, "flowbw for backward flow")->type_name("MODALITY")->capture_default_str();
  app.add_option("--first-frame", o.first_frame, "the number of the first frame")->capture_default_str();
  app.add_option("--frames-from", o.frames_from, "number the frames by the header stamps of this topic")
      ->type_name("TOPIC");
  app.add_option("--deflate-level", o.deflate_level, "0..9; 0 stores the npz entries uncompressed")
      ->capture_default_str();
  app.footer("Exit status: 0 all exported; 1 bad messages skipped (the rest exported); 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  if (o.deflate_level < 0 || o.deflate_level > 9) return viper_tools::usageError(app, "--deflate-level must be 0..9");
  try {
    viper::dataset::viperFramePath(o.out, o.split, o.modality, o.seq, 0, "npz");
  } catch (const std::invalid_argument& e) {
    std::cerr << "export_flow: " << e.what() << "\n";
    return 2;
  }
  try {
    return run(o);
  } catch (const viper::BagReadError& e) {  // a damaged bag (what() names it)
    std::cerr << "\nexport_flow: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "\nexport_flow: " << o.bag << ": " << e.what() << "\n";
    return 2;
  }
}
