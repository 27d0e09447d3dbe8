// `world`: viper's procedural town, a plain OpenGL program (see docs/world.md).
#include "classes.h"
#include "options.h"
#include "oracle_meshes.h"
#include "renderer.h"
#include "route_report.h"
#include "window_context.h"
#include "world_scene.h"

#include "gl_common/headless_egl_context.h"
#include "gl_common/ppm.h"
#include "gl_common/sanitizer_options.h"

#include "viper/ground_truth/oracle.h"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <sys/stat.h>
#include <time.h>

namespace {

// CPU time of the whole process (all of llvmpipe's threads), ms: on a shared machine it shows
// the work a frame costs even when wall time is inflated by other load.
double cpuMs() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// Hash of a mesh's vertices and triangles (this build's std::hash: for comparing runs of one binary).
size_t contentHash(const viper::world::MeshData& m) {
  auto bytes = [](const auto& v) {
    return std::string_view(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0]));
  };
  const std::hash<std::string_view> h;
  return h(bytes(m.positions)) ^ (h(bytes(m.colors)) * 31) ^ (h(bytes(m.indices)) * 1000003);
}

int run(const viper::world::Options& o) {
  using namespace viper::world;
  if (o.print_route) {
    printRoute(o, stdout);
    return 0;
  }
  WorldScene scene(o);
  if (o.list_meshes) {
    std::printf("# mesh_name class_id class_name vertices triangles content_hash (class -1: shared by classes)\n");
    for (int i = 0; i < scene.meshes().size(); ++i) {
      const MeshEntry& m = scene.meshes().at(i);
      std::printf("%s %d %s %zu %zu %016zx\n", m.name.c_str(), m.class_id,
                  m.class_id < 0 ? "shared" : className(uint8_t(m.class_id)), m.data.vertexCount(),
                  m.data.indices.size() / 3, contentHash(m.data));
    }
    return 0;
  }

  if (!o.dump_dir.empty()) {
    struct stat st;
    if (stat(o.dump_dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
      throw std::runtime_error("--dump-dir: '" + o.dump_dir + "' is not a directory");
  }
  WindowContext window;
  std::unique_ptr<viper::gl_common::HeadlessEglContext> headless;
  if (!o.window || !window.open(o.width, o.height)) {
    if (o.window) std::fprintf(stderr, "world: --window: no X11 display (or no X11 in this build), rendering headless\n");
    headless = std::make_unique<viper::gl_common::HeadlessEglContext>(uint32_t(o.width), uint32_t(o.height));
  }
  if (o.benchmark)
    std::printf("world benchmark: OpenGL %s on %s (%s)\n", reinterpret_cast<const char*>(glGetString(GL_VERSION)),
                reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                headless ? headless->platform().c_str() : "X11 window");
  Renderer renderer;
  renderer.init(scene.meshes(), o.width, o.height);
  std::unique_ptr<viper::OracleWriter> oracle;
  if (!o.oracle_path.empty())
    oracle = std::make_unique<viper::OracleWriter>(o.oracle_path, o.width, o.height);

  std::vector<uint8_t> rgb;
  double total_ms = 0, total_cpu_ms = 0;
  int timed = 0;
  for (int f = 0; f < o.frames; ++f) {
    if (f > 0) scene.step();
    viper::OracleFrame frame;
    frame.number = uint64_t(f);
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = cpuMs();
    renderer.record(oracle ? &frame : nullptr);
    scene.render(renderer, oracle ? &frame : nullptr);
    double dump_ms = 0;
    if (!o.dump_dir.empty()) {
      const auto dump_start = std::chrono::steady_clock::now();
      renderer.readPixels(rgb);
      char name[64];
      std::snprintf(name, sizeof(name), "/frame_%06d.ppm", f);
      viper::gl_common::writePpm(o.dump_dir + name, uint32_t(o.width), uint32_t(o.height), rgb);
      dump_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - dump_start).count();
    }
    if (headless) headless->swapBuffers();
    else window.swap();
    if (o.benchmark) {
      // The whole frame: rendering and the swap (where a capture layer reads the frame back), less
      // the dump.
      glFinish();
      double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() - dump_ms;
      if (f > 0 || o.frames == 1) {  // frame 0 includes shader JIT warm-up
        total_ms += ms, ++timed;
        total_cpu_ms += cpuMs() - cpu_start;
      }
    }
    if (oracle) {
      writeNewMeshes(*oracle, scene.meshes(), frame);
      oracle->write(frame);
    }
  }
  if (o.benchmark && timed > 0)
    std::printf("world benchmark: %dx%d %s: %.2f ms/frame (%.1f fps), %.2f CPU ms/frame (all "
                "threads) over %d frames\n",
                o.width, o.height, conditionName(o.condition), total_ms / timed,
                1000.0 * timed / total_ms, total_cpu_ms / timed, timed);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  viper::world::Options options;
  try {
    options = viper::world::parseOptions(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "world: %s\n%s", e.what(), viper::world::usage().c_str());
    return 2;
  }
  if (options.help) {
    std::printf("%s", viper::world::usage().c_str());
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "world: %s\n", e.what());
    return 1;
  }
}
