// capture_to_bag: converts a capture stream (.vcap) into a raw bag holding exactly the messages that
// capture_bridge publishes for it (same topics, types, stamps, sequence numbers and content;
// viper::frameMessages is the bridge's own conversion), without a ROS master, at disk speed. Exit code: 0 = every frame
// written, 1 = problems reported (a damaged stream: the intact frames before it are written; frames
// the bridge would drop), 2 = usage error, the capture cannot be opened or the bag cannot be written.
// docs/capture_bridge.md has the details.
#include "command_line.h"
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

struct Options {
  std::string capture;
  std::string output;
  uint64_t frames = std::numeric_limits<uint64_t>::max();
  std::string compression = "lz4";
  std::string ns = "/capture";
  std::string frame_id = "camera_optical";
  std::optional<double> start_time;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Writes the raw topics capture_bridge publishes for CAPTURE (NS/color/image_raw, NS/color/camera_info,\n"
      "NS/depth/image_raw, NS/depth/camera_info, NS/draw_ids, NS/primitive_ids, NS/draws, and NS/mesh_store\n"
      "whenever a frame brings new meshes, latched) with the bridge's stamps (capture time, or 1 s for the\n"
      "first frame when capture times start at 0, or --start-time); each message is written at its header\n"
      "stamp.",
      "capture_to_bag");
  Options o;
  int64_t frame_count = 0;
  double start_time = 0.0;
  app.add_option("CAPTURE.vcap", o.capture, "the capture stream")->required()->type_name("");
  app.add_option("--output", o.output, "the bag to write")->required()->type_name("OUT.bag");
  const CLI::Option* frames_given = app.add_option("--frames", frame_count, "only the first N frames");
  app.add_option("--compression", o.compression, "the bag's chunks (lz4, as make_test_bag.sh records)")
      ->check(CLI::IsMember({"none", "lz4", "bz2"}))
      ->capture_default_str();
  app.add_option("--namespace", o.ns, "the topics' namespace, starting with '/'")
      ->type_name("NS")
      ->capture_default_str();
  app.add_option("--frame-id", o.frame_id, "the images' frame")->type_name("FRAME")->capture_default_str();
  const CLI::Option* start_time_given =
      app.add_option("--start-time", start_time, "stamp of the first frame, s (> 0), the others after it as captured")
          ->type_name("T");
  app.footer("Exit status: 0 all frames written; 1 problems reported (the intact frames written); 2 usage error,\n"
             "the capture cannot be opened or the bag cannot be written.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  if (*frames_given && frame_count < 1) return viper_tools::usageError(app, "--frames must be >= 1");
  if (*frames_given) o.frames = static_cast<uint64_t>(frame_count);
  if (*start_time_given && !(start_time > 0)) return viper_tools::usageError(app, "--start-time must be > 0");
  if (*start_time_given) o.start_time = start_time;
  if (o.ns.empty() || o.ns[0] != '/') return viper_tools::usageError(app, "--namespace must start with '/'");
  while (o.ns.size() > 1 && o.ns.back() == '/') o.ns.pop_back();

  // The bridge's conversion and stamps for a file replay (CaptureRawFrames), written as its
  // publishers would (writeRawFrame).
  const auto frames = viper_tools::openOrReport<viper::CaptureRawFrames>(app, o.capture, o.start_time, o.frame_id);
  if (!frames) return 2;
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
