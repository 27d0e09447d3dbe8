// test_scene: a small plain OpenGL program (a street with cars, buildings, a skinned person and rain)
// that the capture layer is tested on. It knows nothing of capture; --oracle writes the true
// answers for tests.
#include "frame_output.h"
#include "gl_api.h"
#include "options.h"
#include "program_main.h"
#include "renderer.h"
#include "world.h"

#include "gl_common/headless_egl_context.h"
#include "gl_common/ppm.h"
#include "gl_common/sanitizer_options.h"
#include "viper/ground_truth/oracle.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

namespace {

using namespace viper::scene;

int run(const SceneOptions& o) {
  if (!o.dump_dir.empty()) std::filesystem::create_directories(o.dump_dir);
  viper::gl_common::HeadlessEglContext context(o.width, o.height);
  const GlApi gl = loadGlApi(o.loader);
  std::cerr << "test_scene: " << o.width << "x" << o.height << ", EGL " << context.platform() << ", GL loader "
            << glLoaderName(o.loader) << ", renderer " << reinterpret_cast<const char*>(gl.GetString(GL_RENDERER))
            << "\n";
  const World world(o.seed, static_cast<double>(o.width) / o.height);
  Renderer renderer(gl, world.meshes(), o.width, o.height);
  std::unique_ptr<viper::OracleWriter> oracle;
  if (!o.oracle_path.empty()) oracle = std::make_unique<viper::OracleWriter>(o.oracle_path, o.width, o.height);

  double total_ms = 0.0;
  for (uint64_t n = 0; n < o.frames; ++n) {
    const FrameState state = world.frame(static_cast<double>(n) / o.fps);
    const auto start = std::chrono::steady_clock::now();
    renderer.draw(state);
    if (!o.dump_dir.empty())
      viper::gl_common::writePpm(dumpPath(o.dump_dir, n), o.width, o.height, renderer.readColor());
    if (o.benchmark) gl.Finish();  // time the rendering, not just the command submission
    context.swapBuffers();
    endFrame(o, start, total_ms);
    if (oracle) writeOracleFrame(*oracle, n, state, world);
  }
  if (o.benchmark) std::cout << benchmarkLine(o, total_ms);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return programMain(
      "test_scene", argc, argv, parseOptions, [](const SceneOptions& o) { return o.help ? usage() : std::string(); },
      run);
}
