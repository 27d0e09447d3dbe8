#include "capture_settings.h"

#include "frame_sink.h"

#include <time.h>

#include <cstdlib>
#include <stdexcept>

namespace viper {
namespace capture {
namespace {

std::string envOr(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v ? v : fallback;
}

}  // namespace

double monotonicSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

CaptureSettings readCaptureSettings() {
  CaptureSettings s;
  s.output = envOr("VIPER_CAPTURE_OUTPUT", "");
  s.condition = envOr("VIPER_CAPTURE_CONDITION", "");
  s.profile_path = envOr("VIPER_CAPTURE_PROFILE", "");
  s.frame_limit = std::strtoull(envOr("VIPER_CAPTURE_FRAMES", "0").c_str(), nullptr, 10);
  s.fixed_fps = std::strtod(envOr("VIPER_CAPTURE_FPS", "0").c_str(), nullptr);
  s.skip_frames = std::strtoull(envOr("VIPER_CAPTURE_SKIP", "0").c_str(), nullptr, 10);
  s.start_on_scene = envOr("VIPER_CAPTURE_START_ON_SCENE", "0") == "1";
  s.header.program = envOr("VIPER_CAPTURE_PROGRAM", "");
  // The capture launcher's --codec and --zstd-level (checked there); LZ4 when preloaded by hand.
  const std::string codec = envOr("VIPER_CAPTURE_CODEC", "lz4");
  if (!parseCaptureCodec(codec, s.header.codec))
    throw std::runtime_error("VIPER_CAPTURE_CODEC must be zstd or lz4, not \"" + codec + "\"");
  s.zstd_level = static_cast<int>(std::strtol(envOr("VIPER_CAPTURE_ZSTD_LEVEL", "1").c_str(), nullptr, 10));
  // The capture launcher's --writer-threads (checked there); else half the CPUs less one.
  const std::string threads = envOr("VIPER_CAPTURE_WRITER_THREADS", "");
  s.writer_threads =
      threads.empty() ? FrameSink::defaultThreads() : static_cast<int>(std::strtol(threads.c_str(), nullptr, 10));
  if (s.writer_threads < 1 || s.writer_threads > 64)
    throw std::runtime_error("VIPER_CAPTURE_WRITER_THREADS must be 1 to 64, not \"" + threads + "\"");
  s.readback = envOr("VIPER_CAPTURE_READBACK", "auto");
  if (s.readback != "sync" && s.readback != "async" && s.readback != "auto")
    throw std::runtime_error("VIPER_CAPTURE_READBACK must be auto, sync or async, not \"" + s.readback + "\"");
  return s;
}

}  // namespace capture
}  // namespace viper
