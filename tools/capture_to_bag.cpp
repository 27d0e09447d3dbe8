// capture_to_bag: converts a capture stream (.vcap) into a raw bag holding exactly the messages that
// capture_bridge publishes for it (same topics, types, stamps, sequence numbers and content;
// viper::frameMessages is the bridge's own conversion), without a ROS master, at disk speed. Exit code: 0 = every frame
// written, 1 = problems reported (a damaged stream: the intact frames before it are written; frames
// the bridge would drop), 2 = usage error, the capture cannot be opened or the bag cannot be written.
// docs/capture_bridge.md has the details.
#include "viper/capture/capture_stream.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/bridge/bag_writer.h"
#include "viper/ros/bridge/raw_frames.h"


#include <chrono>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace {

const char* kUsage =
    "usage: capture_to_bag CAPTURE.vcap --output OUT.bag [--frames N] [--compression none|lz4|bz2]\n"
    "                      [--namespace /capture] [--frame-id camera_optical] [--start-time T]\n"
    "Writes the raw topics capture_bridge publishes for CAPTURE (NS/color/image_raw, NS/color/camera_info,\n"
    "NS/depth/image_raw, NS/depth/camera_info, NS/draw_ids, NS/primitive_ids, NS/draws, and NS/mesh_store\n"
    "whenever a frame brings new meshes, latched) with the bridge's stamps (capture time, or 1 s for the\n"
    "first frame when capture times start at 0, or --start-time); each message is written at its header\n"
    "stamp. --frames N: only the first N frames. Default compression: lz4 (as make_test_bag.sh records).\n"
    "Exit code: 0 all frames written, 1 problems reported (the intact frames written), 2 error.\n";

struct Options {
  std::string capture;
  std::string output;
  uint64_t frames = std::numeric_limits<uint64_t>::max();
  std::string compression = "lz4";
  std::string ns = "/capture";
  std::string frame_id = "camera_optical";
  std::optional<double> start_time;
};

// Parses the command line; returns the error, empty if none.
std::string parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0) {
      if (!o.capture.empty()) return "more than one capture given ('" + o.capture + "', '" + arg + "')";
      o.capture = arg;
      continue;
    }
    if (i + 1 >= argc) return "missing value after " + arg;
    const std::string v = argv[++i];
    try {
      if (arg == "--output") o.output = v;
      else if (arg == "--frames") {
        const long long n = std::stoll(v);
        if (n < 1) return "--frames must be >= 1";
        o.frames = static_cast<uint64_t>(n);
      } else if (arg == "--compression") o.compression = v;
      else if (arg == "--namespace") o.ns = v;
      else if (arg == "--frame-id") o.frame_id = v;
      else if (arg == "--start-time") o.start_time = std::stod(v);
      else return "unknown option " + arg;
    } catch (const std::exception&) {
      return "bad number '" + v + "' for " + arg;
    }
  }
  if (o.capture.empty() || o.output.empty()) return "a capture and --output are required";
  if (o.compression != "none" && o.compression != "lz4" && o.compression != "bz2")
    return "--compression must be none, lz4 or bz2";
  if (o.start_time && !(*o.start_time > 0)) return "--start-time must be > 0";
  if (o.ns.empty() || o.ns[0] != '/') return "--namespace must start with '/'";
  while (o.ns.size() > 1 && o.ns.back() == '/') o.ns.pop_back();
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    }
  }
  Options o;
  const std::string error = parse(argc, argv, o);
  if (!error.empty()) {
    std::cerr << "capture_to_bag: " << error << "\n" << kUsage;
    return 2;
  }

  // The bridge's conversion and stamps for a file replay (CaptureRawFrames), written as its
  // publishers would (writeRawFrame).
  std::unique_ptr<viper::CaptureRawFrames> frames;
  try {
    frames = std::make_unique<viper::CaptureRawFrames>(o.capture, o.start_time, o.frame_id);
  } catch (const std::exception& e) {
    std::cerr << "capture_to_bag: " << e.what() << "\n";
    return 2;
  }
  std::unique_ptr<viper::BagWriter> out;
  try {
    out = std::make_unique<viper::BagWriter>(o.output, o.compression, "/capture_to_bag");
  } catch (const std::exception& e) {
    std::cerr << "capture_to_bag: cannot write '" << o.output << "': " << e.what() << "\n";
    return 2;
  }

  const auto start = std::chrono::steady_clock::now();
  uint64_t written = 0;
  size_t problems_told = 0, warnings_told = 0;
  auto tell = [&] {  // what the reader found since the last frame, as it happens
    for (; warnings_told < frames->warnings().size(); ++warnings_told)
      std::cerr << "capture_to_bag: " << frames->warnings()[warnings_told] << "\n";
    for (; problems_told < frames->problems().size(); ++problems_told)
      std::cerr << "capture_to_bag: " << frames->problems()[problems_told] << "\n";
  };
  try {
    viper::FrameMessages m;
    while (written < o.frames && frames->next(m)) {
      tell();
      viper::writeRawFrame(*out, o.ns, m);
      ++written;
    }
    tell();
    out->close();
  } catch (const std::exception& e) {
    std::cerr << "capture_to_bag: writing '" << o.output << "' failed: " << e.what() << "\n";
    return 2;
  }
  const size_t problems = frames->problems().size();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "capture_to_bag: wrote " << written << " frames, " << out->messages() << " messages ("
            << out->bytes() / 1e6 << " MB) of " << o.capture << " to " << o.output << " in " << s << " s ("
            << written / s << " frames/s); " << problems << " problems\n";
  return problems == 0 ? 0 : 1;
}
