// `capture [options] -- PROGRAM ARGS...`: runs an OpenGL or Vulkan program with the viper
// interceptor preloaded and the Vulkan layer enabled, and writes a capture stream (one layer writes
// it: the OpenGL interceptor claims it at the program's first call it intercepts, the Vulkan layer
// at its first frame, whichever comes first), then reads the stream back and prints its verdict (frames,
// share of the scene with ids and placed, the main reason for what was not recorded). Exit status:
// the program's (128 + signal if killed), or 74 when the program succeeded but the capture could not
// be written (a full disk): the layer says so through a pipe (VIPER_CAPTURE_STATUS_FD) and the
// stream ends with the last frame written whole; or 65 when the program succeeded but the capture
// is mostly empty by --require-ids.
#include "command_line.h"
#include "viper/capture/capture_profile.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/capture_verdict.h"

#include <elf.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace {

pid_t g_child = 0;

// Exit status when the program succeeded but the capture is mostly empty (--require-ids).
constexpr int kExitMostlyEmpty = 65;

void forwardSignal(int sig) {
  if (g_child > 0) kill(g_child, sig);
}

// What a check of an option says when `value` is not `what` (naming `env`, the environment variable
// that may have given it).
std::string mustBe(const std::string& what, const std::string& value, const std::string& env) {
  return "must be " + what + ", not '" + value + "'" + (env.empty() ? "" : " (the option or " + env + ")");
}

// A check of a value passed on to the layer as written: a whole number (base 10), or with `real`
// any number, from `min` (above it with `above_min`) to `max`; `what` says so when it is not (and
// `env`, the environment variable that may have given it).
CLI::Validator numberCheck(bool real, double min, bool above_min, double max, const std::string& what,
                           const std::string& env = "") {
  return CLI::Validator(
      [=](std::string& value) -> std::string {
        char* end = nullptr;
        const double n =
            real ? std::strtod(value.c_str(), &end) : static_cast<double>(std::strtoll(value.c_str(), &end, 10));
        const bool ok = !value.empty() && !*end && (above_min ? n > min : n >= min) && n <= max;
        return ok ? "" : mustBe(what, value, env);
      },
      "");
}

// A check of a value that must be one of `choices`; `what` names them when it is not (and `env`, the
// environment variable that may have given it).
CLI::Validator choiceCheck(const std::vector<std::string>& choices, const std::string& what, const std::string& env) {
  return CLI::Validator(
      [=](std::string& value) -> std::string {
        const bool ok = std::find(choices.begin(), choices.end(), value) != choices.end();
        return ok ? "" : mustBe(what, value, env);
      },
      "");
}

std::string executableDir() {
  char buf[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return ".";
  std::string path(buf, static_cast<size_t>(n));
  return path.substr(0, path.rfind('/'));
}

std::string findLibrary(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* env = std::getenv("VIPER_INTERCEPT_LIBRARY")) return env;
  const std::string dir = executableDir();
  for (const std::string& candidate :
       {dir + "/libviper_intercept.so", dir + "/../libviper_intercept.so", std::string(VIPER_INTERCEPT_BUILD_PATH)}) {
    if (access(candidate.c_str(), R_OK) == 0) return candidate;
  }
  return std::string(VIPER_INTERCEPT_BUILD_PATH);
}

constexpr const char* kVulkanLayerName = "VK_LAYER_VIPER_capture";

// The folder holding the Vulkan layer's manifest: $VIPER_VULKAN_LAYER_PATH, else the package's share
// folder next to this binary (devel or install space), else the build's.
std::string findVulkanLayerFolder() {
  if (const char* env = std::getenv("VIPER_VULKAN_LAYER_PATH")) return env;
  const std::string dir = executableDir();
  for (const std::string& candidate : {dir + "/../../share/viper/vulkan", std::string(VIPER_VULKAN_LAYER_BUILD_PATH)}) {
    if (access((candidate + "/" + kVulkanLayerName + ".json").c_str(), R_OK) == 0) return candidate;
  }
  return "";
}

// $name set to `value` for the layer, or unset where `value` is empty (the layer's default then).
void setOrUnsetEnv(const char* name, const std::string& value) {
  if (!value.empty()) setenv(name, value.c_str(), 1);
  else unsetenv(name);
}

std::string absolute(const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  char cwd[PATH_MAX];
  return getcwd(cwd, sizeof(cwd)) ? std::string(cwd) + "/" + path : path;
}

bool isRuntime(const std::string& base) {
  return base.rfind("libasan", 0) == 0 || base.rfind("libtsan", 0) == 0 || base.rfind("libubsan", 0) == 0 ||
         base.rfind("liblsan", 0) == 0;
}

// The sanitizer runtimes that must come first in a program that `lib` is preloaded into (its
// DT_NEEDED libasan or libtsan: a layer built by scripts/sanitize.sh or viper_intercept_asan), as
// their sonames ("libasan.so.8"); none for the normal layer. Loaded only as the layer's dependency,
// a runtime comes after libc: ASan refuses to start, and neither would see the program's malloc and
// locks.
std::vector<std::string> runtimesNeeded(const std::string& lib) {
  std::vector<std::string> needed;
  const int fd = open(lib.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return needed;
  auto readAt = [fd](void* to, size_t size, uint64_t at) {
    return pread(fd, to, size, static_cast<off_t>(at)) == static_cast<ssize_t>(size);
  };
  Elf64_Ehdr eh;
  if (readAt(&eh, sizeof(eh), 0) && std::memcmp(eh.e_ident, ELFMAG, SELFMAG) == 0 && eh.e_ident[EI_CLASS] == ELFCLASS64 &&
      eh.e_shentsize == sizeof(Elf64_Shdr)) {
    std::vector<Elf64_Shdr> sections(eh.e_shnum);
    if (readAt(sections.data(), sections.size() * sizeof(Elf64_Shdr), eh.e_shoff)) {
      for (const Elf64_Shdr& dynamic : sections) {
        if (dynamic.sh_type != SHT_DYNAMIC || dynamic.sh_link >= sections.size()) continue;
        const Elf64_Shdr& strings = sections[dynamic.sh_link];
        std::vector<Elf64_Dyn> entries(dynamic.sh_size / sizeof(Elf64_Dyn));
        std::vector<char> names(strings.sh_size + 1, '\0');
        if (!readAt(entries.data(), entries.size() * sizeof(Elf64_Dyn), dynamic.sh_offset) ||
            !readAt(names.data(), strings.sh_size, strings.sh_offset))
          break;
        for (const Elf64_Dyn& d : entries) {
          if (d.d_tag != DT_NEEDED || d.d_un.d_val >= strings.sh_size) continue;
          const std::string name = names.data() + d.d_un.d_val;
          if (name.rfind("libasan", 0) == 0 || name.rfind("libtsan", 0) == 0) needed.push_back(name);
        }
      }
    }
  }
  close(fd);
  return needed;
}

// LD_PRELOAD for the program: the interceptor first, then what was preloaded already; a sanitizer
// runtime given there (libasan, to run a sanitized build of the interceptor) stays before it, as a
// runtime must come before the libraries it instruments. When none is given, the runtimes the
// interceptor itself needs (`runtimes_needed`) come first.
std::string preloadList(const std::string& lib, const char* old, const std::vector<std::string>& runtimes_needed) {
  std::string runtimes, rest;
  std::string entries = old ? old : "";
  for (char& c : entries)
    if (c == ' ') c = ':';
  size_t start = 0;
  while (start <= entries.size()) {
    size_t end = entries.find(':', start);
    if (end == std::string::npos) end = entries.size();
    const std::string entry = entries.substr(start, end - start);
    start = end + 1;
    if (entry.empty()) continue;
    const size_t slash = entry.rfind('/');
    const std::string base = slash == std::string::npos ? entry : entry.substr(slash + 1);
    (isRuntime(base) ? runtimes : rest) += entry + ":";
  }
  if (runtimes.empty())
    for (const std::string& r : runtimes_needed) runtimes += r + ":";
  std::string list = runtimes + lib;
  if (!rest.empty()) list += ":" + rest.substr(0, rest.size() - 1);
  return list;
}

// What identifies a file's contents well enough to tell whether the program wrote it: a stream an
// earlier run left at the output path is not this run's when the program never opened it.
struct FileStamp {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  off_t size = 0;
  timespec modified{};
};

FileStamp fileStamp(const std::string& path) {
  FileStamp f;
  struct stat st;
  if (stat(path.c_str(), &st) != 0) return f;
  f = {true, st.st_dev, st.st_ino, st.st_size, st.st_mtim};
  return f;
}

bool sameStamp(const FileStamp& a, const FileStamp& b) {
  return a.exists == b.exists && a.device == b.device && a.inode == b.inode && a.size == b.size &&
         a.modified.tv_sec == b.modified.tv_sec && a.modified.tv_nsec == b.modified.tv_nsec;
}

// Prints the verdict of the capture at `output` (written by this run unless its stamp is `before`'s)
// and returns whether it meets --require-ids (`required_id_share` < 0: none asked).
bool printVerdict(const std::string& output, const FileStamp& before, double required_id_share, bool start_on_scene,
                  const std::string& skip) {
  viper::CaptureReadResult read;
  std::string why_no_frames;
  const FileStamp after = fileStamp(output);
  if (!after.exists || sameStamp(before, after)) {
    why_no_frames = "the program wrote no capture stream (no frame reached a layer: not an OpenGL or Vulkan "
                    "program, or it failed before its first frame)";
  } else {
    try {
      read = viper::readCaptureCoverage(output);
    } catch (const std::exception& e) {
      read.problem = e.what();
    }
    if (start_on_scene)
      why_no_frames = "the scene never started (--start-on-scene: no recorded draw had the camera's view and "
                      "projection)";
    else if (!skip.empty() && skip != "0")
      why_no_frames = "no buffer swap after the " + skip + " frames skipped (--skip-frames)";
    else
      why_no_frames = "the program swapped no buffers";
  }
  std::fprintf(stderr, "capture: %s: %s\n", output.c_str(), viper::captureVerdict(read, why_no_frames).c_str());
  if (required_id_share < 0.0) return true;
  const viper::CaptureCoverage& c = read.coverage;
  if (c.frames > 0 && c.idShare() >= required_id_share) return true;
  if (c.frames)
    std::fprintf(stderr, "capture: %s: ids on %.1f%% of scene pixels, below --require-ids %g\n", output.c_str(),
                 100.0 * c.idShare(), required_id_share);
  else
    std::fprintf(stderr, "capture: %s: no frame written, against --require-ids %g\n", output.c_str(),
                 required_id_share);
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "capture [options] -- PROGRAM [ARGS...]: runs an OpenGL or Vulkan PROGRAM with the viper interceptor\n"
      "preloaded and the Vulkan layer enabled, and writes its capture stream; everything after -- is the\n"
      "program and its arguments, passed as they are.",
      "capture");
  std::string output, profile, condition, frames, library, fps, skip, codec, zstd_level, writer_threads, readback,
      require_ids;
  bool start_on_scene = false;
  std::vector<std::string> program;
  constexpr double kNoLimit = std::numeric_limits<double>::infinity();
  app.add_option("-o,--output", output, "the capture stream to write")->required()->type_name("FILE.vcap");
  app.add_option("--profile", profile,
                 "where the program keeps its matrices (docs/capture_layer.md); without one no matrices are "
                 "recorded")
      ->type_name("PROFILE.yaml");
  app.add_option("--condition", condition, "condition stored in every frame (day, rain, ...)")->type_name("TAG");
  app.add_option("--frames", frames, "write N frames, then stop the program")
      ->type_name("N")
      ->check(numberCheck(false, 1, false, kNoLimit, "a positive integer"));
  app.add_option("--fps", fps,
                 "stamp frame n at n / F seconds, for programs that advance a fixed time step per frame "
                 "(default: the monotonic clock at each buffer swap)")
      ->type_name("F")
      ->check(numberCheck(true, 0, true, 1e6, "a positive number"));
  app.add_option("--skip-frames", skip, "show but do not write the first N frames (menus, loading screens)")
      ->type_name("N")
      ->check(numberCheck(false, 0, false, kNoLimit, "a non-negative integer"));
  app.add_flag("--start-on-scene", start_on_scene,
               "write from the first frame in which a recorded draw has the camera's view and projection "
               "matrices (the profile's scene programs)");
  app.add_option("--codec", codec,
                 "compression of the stream (default lz4); lz4 takes half the CPU to write and to read (what a "
                 "replay of the whole 1080p pipeline needs to near 60 frames/s on two cores); zstd makes files "
                 "half the size, for captures kept long")
      ->type_name("zstd|lz4")
      ->envname("VIPER_CAPTURE_CODEC")
      ->check(choiceCheck({"zstd", "lz4"}, "zstd or lz4", "$VIPER_CAPTURE_CODEC"));
  app.add_option("--zstd-level", zstd_level,
                 "with zstd, its level, -131072 to 22 (default 1: the world at 1920x1080 takes 1.5 MB a frame, "
                 "19 ms of the writer thread; -7: 2.4 MB, 16 ms; 3: 1.4 MB, 25 ms)")
      ->type_name("L")
      ->envname("VIPER_CAPTURE_ZSTD_LEVEL")
      ->check(numberCheck(false, -131072, false, 22, "an integer from -131072 to 22", "$VIPER_CAPTURE_ZSTD_LEVEL"));
  app.add_option("--writer-threads", writer_threads,
                 "threads that finish, compress and write frames, 1 to 64 (default half the CPUs less one, 1 to "
                 "8); the stream is the same whatever N")
      ->type_name("N")
      ->envname("VIPER_CAPTURE_WRITER_THREADS")
      ->check(numberCheck(false, 1, false, 64, "an integer from 1 to 64", "$VIPER_CAPTURE_WRITER_THREADS"));
  app.add_option("--readback", readback,
                 "read each frame back at its swap (sync), or into buffers the GPU fills while the program goes "
                 "on, handed over at the next swap (async; needs glBufferStorage); auto (default): async except "
                 "on software renderers (llvmpipe). The stream is the same either way")
      ->type_name("auto|sync|async")
      ->envname("VIPER_CAPTURE_READBACK")
      ->check(choiceCheck({"auto", "sync", "async"}, "auto, sync or async", "$VIPER_CAPTURE_READBACK"));
  app.add_option("--require-ids", require_ids,
                 "F from 0 to 1; the capture passes when at least one frame was written and at least F of its "
                 "scene pixels (depth below 1 or a draw id, over all frames) have a draw id")
      ->type_name("F")
      ->check(numberCheck(true, 0, false, 1, "a number from 0 to 1"));
  app.add_option("--library", library,
                 "the interceptor to preload (default $VIPER_INTERCEPT_LIBRARY, else the one next to capture, "
                 "else the build tree's)")
      ->type_name("libviper_intercept.so");
  app.add_option("PROGRAM", program, "after --: the program to run and its arguments, passed as they are")
      ->type_name("");
  app.footer(
      "The defaults of --codec, --zstd-level, --writer-threads and --readback come from their environment\n"
      "variables when set (Env above).\n"
      "After the program exits, one line 'capture: FILE: N frames written; ids on I% of scene pixels, placed\n"
      "P%; R draws recorded, U not; left out: REASON' (or 'nothing left out'; '0 frames written: WHY').\n"
      "Exit status: the program's (128 + signal if killed); else 74 (EX_IOERR) if the capture could not be\n"
      "written (e.g. a full disk; the stream keeps the frames written before); else 65 if --require-ids\n"
      "was not met; else 0; 2 for a usage error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  // The program is what follows the first --, exactly (nothing before it is the program's).
  const int i = static_cast<int>(std::find(argv + 1, argv + argc, std::string("--")) - argv) + 1;
  if (i >= argc) return viper_tools::usageError(app, "no program given after --");
  if (program.size() != static_cast<size_t>(argc - i))
    return viper_tools::usageError(app, "the program and its arguments go after --, not before it");
  double required_id_share = -1.0;  // none asked
  if (!require_ids.empty()) required_id_share = std::strtod(require_ids.c_str(), nullptr);
  if (!profile.empty()) {
    try {
      viper::loadCaptureProfile(profile);  // fail here, clearly, rather than inside the program
    } catch (const std::exception& e) {
      std::fprintf(stderr, "capture: %s\n", e.what());
      return 2;
    }
  }
  const std::string lib = absolute(findLibrary(library));
  if (access(lib.c_str(), R_OK) != 0) {
    std::fprintf(stderr, "capture: interceptor library %s not found (use --library)\n", lib.c_str());
    return 2;
  }

  setenv("LD_PRELOAD", preloadList(lib, std::getenv("LD_PRELOAD"), runtimesNeeded(lib)).c_str(), 1);
  // Vulkan programs: the loader finds the layer's manifest and enables the layer by name.
  const std::string vulkan_layers = findVulkanLayerFolder();
  if (!vulkan_layers.empty()) {
    const char* paths = std::getenv("VK_ADD_LAYER_PATH");
    setenv("VK_ADD_LAYER_PATH", (vulkan_layers + (paths && *paths ? std::string(":") + paths : "")).c_str(), 1);
    const char* layers = std::getenv("VK_INSTANCE_LAYERS");
    setenv("VK_INSTANCE_LAYERS",
           (std::string(kVulkanLayerName) + (layers && *layers ? std::string(":") + layers : "")).c_str(), 1);
  } else {
    std::fprintf(stderr, "capture: the Vulkan layer's manifest (%s.json) was not found: Vulkan programs are not captured\n",
                 kVulkanLayerName);
  }
  unsetenv("VIPER_CAPTURE_CLAIMED_BY");
  setenv("VIPER_CAPTURE_OUTPUT", absolute(output).c_str(), 1);
  setenv("VIPER_CAPTURE_PROGRAM", argv[i], 1);
  setOrUnsetEnv("VIPER_CAPTURE_PROFILE", absolute(profile));
  setenv("VIPER_CAPTURE_CONDITION", condition.c_str(), 1);
  setOrUnsetEnv("VIPER_CAPTURE_FRAMES", frames);
  setOrUnsetEnv("VIPER_CAPTURE_FPS", fps);
  setOrUnsetEnv("VIPER_CAPTURE_SKIP", skip);
  setenv("VIPER_CAPTURE_START_ON_SCENE", start_on_scene ? "1" : "0", 1);
  setOrUnsetEnv("VIPER_CAPTURE_CODEC", codec);
  setOrUnsetEnv("VIPER_CAPTURE_ZSTD_LEVEL", zstd_level);
  setOrUnsetEnv("VIPER_CAPTURE_WRITER_THREADS", writer_threads);
  setOrUnsetEnv("VIPER_CAPTURE_READBACK", readback);

  // The layer's report of a capture that failed while the program ran (read without blocking:
  // the program's own children may keep the write end open).
  int status_pipe[2] = {-1, -1};
  if (pipe(status_pipe) == 0) {
    fcntl(status_pipe[0], F_SETFD, FD_CLOEXEC);
    fcntl(status_pipe[0], F_SETFL, O_NONBLOCK);
    setenv("VIPER_CAPTURE_STATUS_FD", std::to_string(status_pipe[1]).c_str(), 1);
  }

  const FileStamp before = fileStamp(output);
  g_child = fork();
  if (g_child < 0) {
    std::perror("capture: fork");
    return 1;
  }
  if (g_child == 0) {
    execvp(argv[i], argv + i);
    std::fprintf(stderr, "capture: cannot run %s: %s\n", argv[i], std::strerror(errno));
    _exit(127);
  }
  signal(SIGINT, forwardSignal);
  signal(SIGTERM, forwardSignal);
  int status = 0;
  while (waitpid(g_child, &status, 0) < 0) {
    if (errno != EINTR) {
      std::perror("capture: waitpid");
      return 1;
    }
  }
  std::string failure;
  if (status_pipe[0] >= 0) {
    close(status_pipe[1]);
    char buffer[4096];
    ssize_t n;
    while ((n = read(status_pipe[0], buffer, sizeof buffer)) > 0) failure.append(buffer, static_cast<size_t>(n));
  }
  if (!failure.empty())
    std::fprintf(stderr, "capture: %s: %s", output.c_str(), failure.c_str());
  const bool required = printVerdict(output, before, required_id_share, start_on_scene, skip);
  if (WIFEXITED(status)) {
    if (WEXITSTATUS(status) != 0) return WEXITSTATUS(status);
    if (!failure.empty()) return 74;
    return required ? 0 : kExitMostlyEmpty;
  }
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}
