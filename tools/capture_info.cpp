// capture_info: prints what a capture stream holds (frames, sizes, draws, meshes, conditions), and
// reports the first damaged chunk if any. Exit code 0 = intact, 1 = damaged, 2 = usage/open error.
#include "command_line.h"
#include "viper/capture/capture_stream.h"

#include <cstdio>
#include <iostream>
#include <map>
#include <set>
#include <string>

namespace {

struct Summary {
  uint64_t frames = 0, draws = 0, visible_draws = 0, deformed_draws = 0, meshes = 0;
  uint64_t first_frame = 0, last_frame = 0;
  double first_time_s = 0.0, last_time_s = 0.0;
  uint32_t width = 0, height = 0;
  std::set<uint64_t> programs, textures;
  std::map<std::string, uint64_t> conditions;

  void add(const viper::CaptureFrame& f) {
    if (frames == 0) {
      first_frame = f.number;
      first_time_s = f.time_s;
      width = f.width;
      height = f.height;
    }
    ++frames;
    last_frame = f.number;
    last_time_s = f.time_s;
    ++conditions[f.condition.empty() ? "(none)" : f.condition];
    meshes += f.new_meshes.size();
    for (const auto& d : f.draws) {
      ++draws;
      visible_draws += d.visible_pixels > 0;
      deformed_draws += !d.deformed_clip_xyzw.empty();
      programs.insert(d.program_key);
      textures.insert(d.texture_keys.begin(), d.texture_keys.end());
    }
  }

  void print(const viper::CaptureReader& reader) const {
    std::cout << "file:        " << reader.path() << " (" << reader.offset() << " bytes read)\n"
              << "program:     " << reader.header().program << "\n"
              << "profile:     " << reader.header().profile << "\n"
              << "version:     " << reader.header().version << " (" << viper::captureCodecName(reader.header().codec)
              << ")\n"
              << "frames:      " << frames;
    if (frames > 0) {
      std::cout << " (numbers " << first_frame << ".." << last_frame << ", "
                << (last_time_s - first_time_s) << " s";
      if (frames > 1) std::cout << ", " << (frames - 1) / (last_time_s - first_time_s) << " fps";
      std::cout << ")";
    }
    std::cout << "\nsize:        " << width << "x" << height << "\nconditions: ";
    for (const auto& c : conditions) std::cout << " " << c.first << "=" << c.second;
    std::cout << "\ndraws:       " << draws << " (" << visible_draws << " visible, " << deformed_draws
              << " deformed)"
              << "\nmeshes:      " << meshes << "\nprograms:    " << programs.size()
              << "\ntextures:    " << textures.size() << "\n";
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Prints a summary of a viper capture stream and checks every chunk's checksum.", "capture_info");
  std::string path;
  app.add_option("FILE.vcap", path, "the capture stream")->required()->type_name("");
  app.footer("Exit status: 0 intact; 1 damaged (the summary up to the damage, then where it is); 2 usage or open\n"
             "error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  const auto reader = viper_tools::openOrReport<viper::CaptureReader>(app, path);
  if (!reader) return 2;
  Summary summary;
  viper::CaptureFrame frame;
  try {
    while (reader->next(frame) == viper::CaptureReader::Status::kFrame) summary.add(frame);
  } catch (const std::exception& e) {
    summary.print(*reader);
    std::cout << "damaged:     " << e.what() << "\n";
    return 1;
  }
  summary.print(*reader);
  std::cout << "intact:      yes\n";
  return 0;
}
