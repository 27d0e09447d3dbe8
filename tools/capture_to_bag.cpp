// capture_to_bag: converts a capture stream (.vcap) into a raw bag holding exactly the messages that
// capture_bridge publishes for it (same topics, types, stamps, sequence numbers and content;
// viper::frameMessages is the bridge's own conversion), without a ROS master, at disk speed. Exit code: 0 = every frame
// written, 1 = problems reported (a damaged stream: the intact frames before it are written; frames
// the bridge would drop), 2 = usage error, the capture cannot be opened or the bag cannot be written.
// docs/capture_bridge.md has the details.
#include "viper/capture/capture_stream.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/bridge/bag_writer.h"
#include "viper/ros/bridge/replay_timing.h"


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

// The bridge's raw topics under its namespace, written as its publishers would (BagWriter).
class RawBagWriter {
 public:
  RawBagWriter(const std::string& path, const std::string& compression, const std::string& ns)
      : bag_(path, compression, "/capture_to_bag"), ns_(ns == "/" ? "" : ns) {}
  template <typename M>
  void write(const std::string& name, const boost::shared_ptr<M>& msg, bool latched = false) {
    bag_.write(ns_ + "/" + name, msg, latched);
  }
  void close() { bag_.close(); }
  uint64_t messages() const { return bag_.messages(); }
  uint64_t bytes() const { return bag_.bytes(); }

 private:
  viper::BagWriter bag_;
  std::string ns_;
};

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

  std::unique_ptr<viper::CaptureReader> reader;
  try {
    reader = std::make_unique<viper::CaptureReader>(o.capture);
  } catch (const std::exception& e) {
    std::cerr << "capture_to_bag: cannot read capture '" << o.capture << "': " << e.what() << "\n";
    return 2;
  }
  std::unique_ptr<RawBagWriter> out;
  try {
    out = std::make_unique<RawBagWriter>(o.output, o.compression, o.ns);
  } catch (const std::exception& e) {
    std::cerr << "capture_to_bag: cannot write '" << o.output << "': " << e.what() << "\n";
    return 2;
  }

  const auto start = std::chrono::steady_clock::now();
  // The bridge's stamps for a file replay: rate 0 paces nothing, stamps depend on capture time only.
  viper::ReplayTiming timing(0.0, o.start_time);
  viper::MeshStoreAccumulator meshes;
  viper::CaptureFrame frame;
  uint64_t written = 0, problems = 0;
  std::optional<uint64_t> last_number;
  bool camera_warned = false;
  try {
    while (written < o.frames) {
      const uint64_t offset = reader->offset();
      try {
        if (reader->next(frame) == viper::CaptureReader::Status::kEnd) break;
      } catch (const viper::CaptureFormatError& e) {
        std::cerr << "capture_to_bag: capture '" << o.capture << "' is damaged at byte " << e.offset() << " (after "
                  << (last_number ? "frame " + std::to_string(*last_number) : std::string("no frame")) << "; " << written
                  << " frames written): " << e.what() << "\n";
        ++problems;
        break;
      }
      const std::string problem = viper::validateFrame(frame);
      if (!problem.empty()) {
        std::cerr << "capture_to_bag: dropping frame " << frame.number << " of '" << o.capture << "' (byte " << offset
                  << "): " << problem << "\n";
        ++problems;
        continue;
      }
      std_msgs::Header header;
      header.stamp = ros::Time(timing.stampOf(frame.time_s));
      header.frame_id = o.frame_id;
      if (timing.lastWasClamped()) {
        std::cerr << "capture_to_bag: frame " << frame.number << " of '" << o.capture << "' goes back in time ("
                  << frame.time_s << " s); stamped 1 ms after the previous frame\n";
      }
      viper::FrameMessages m;
      try {
        m = viper::frameMessages(frame, header, meshes);
      } catch (const std::invalid_argument& e) {
        std::cerr << "capture_to_bag: dropping frame " << frame.number << " of '" << o.capture << "' (byte " << offset
                  << "): " << e.what() << "\n";
        ++problems;
        continue;
      }
      if (!m.camera_problem.empty() && !camera_warned) {
        camera_warned = true;
        std::cerr << "capture_to_bag: frame " << frame.number << " of '" << o.capture << "': " << m.camera_problem << "\n";
      }
      // The bridge's publication order.
      if (m.mesh_store) out->write("mesh_store", m.mesh_store, /*latched=*/true);
      out->write("color/image_raw", m.color);
      out->write("color/camera_info", m.camera_info);
      out->write("depth/image_raw", m.depth);
      out->write("depth/camera_info", m.camera_info);
      out->write("draw_ids", m.draw_ids);
      out->write("primitive_ids", m.primitive_ids);
      out->write("draws", m.draws);
      last_number = frame.number;
      ++written;
    }
    out->close();
  } catch (const std::exception& e) {
    std::cerr << "capture_to_bag: writing '" << o.output << "' failed: " << e.what() << "\n";
    return 2;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "capture_to_bag: wrote " << written << " frames, " << out->messages() << " messages ("
            << out->bytes() / 1e6 << " MB) of " << o.capture << " to " << o.output << " in " << s << " s ("
            << written / s << " frames/s); " << problems << " problems\n";
  return problems == 0 ? 0 : 1;
}
