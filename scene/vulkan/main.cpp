// vk_test_scene: test_scene's scene drawn with Vulkan into an X window (or, --headless, into images
// of its own that nothing presents), the program the Vulkan capture layer is tested on. It knows
// nothing of capture; --oracle writes the same true answers as test_scene (OpenGL conventions),
// --dump-dir the presented (headless: the drawn) images.
#include "vk_context.h"
#include "vk_options.h"
#include "vk_renderer.h"

#include "gl_common/ppm.h"
#include "gl_common/sanitizer_options.h"
#include "scene/frame_output.h"
#include "scene/program_main.h"
#include "scene/world.h"
#include "viper/ground_truth/oracle.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

namespace {

using namespace viper::scene;

const char* presentModeName(VkPresentModeKHR mode) {
  return mode == VK_PRESENT_MODE_IMMEDIATE_KHR ? "IMMEDIATE" : "FIFO";
}

int run(const VkSceneOptions& options) {
  const SceneOptions& o = options.scene;
  if (!o.dump_dir.empty()) std::filesystem::create_directories(o.dump_dir);
  vk::Context context(o.width, o.height, options.dynamic_rendering, options.render_pass2, options.headless);
  vk::Swapchain swapchain(context, o.width, o.height, !o.dump_dir.empty());
  std::cerr << "vk_test_scene: " << o.width << "x" << o.height << ", " << context.description() << ", "
            << swapchain.imageCount()
            << (options.headless ? " images of its own, headless (no window, nothing presented)"
                                 : std::string(" swapchain images, ") + presentModeName(swapchain.presentMode()))
            << (options.dynamic_rendering ? ", dynamic rendering" : ", render passes")
            << (options.offscreen ? ", offscreen + composite + HUD" : "")
            << (options.host_visible_buffers ? ", host-visible buffers" : ", staged device-local buffers")
            << (options.full_push_constants ? ", push constants full" : "")
            << (options.render_pass2 ? ", render pass 2, imageless framebuffers, vkQueueSubmit2" : "") << "\n";

  const World world(o.seed, static_cast<double>(o.width) / o.height);
  size_t skinned_draws = 0;
  for (const DrawItem& item : world.frame(0).draws) skinned_draws += item.program == ProgramKind::kSkinned;
  vk::RenderModes modes;
  modes.dynamic_rendering = options.dynamic_rendering;
  modes.offscreen = options.offscreen;
  modes.host_visible_buffers = options.host_visible_buffers;
  modes.full_push_constants = options.full_push_constants;
  modes.render_pass2 = options.render_pass2;
  modes.readable = !o.dump_dir.empty();
  vk::Renderer renderer(context, swapchain, world.meshes(), skinned_draws, modes);
  std::unique_ptr<viper::OracleWriter> oracle;
  if (!o.oracle_path.empty()) oracle = std::make_unique<viper::OracleWriter>(o.oracle_path, o.width, o.height);

  double total_ms = 0.0;
  std::vector<uint8_t> rgb;
  for (uint64_t n = 0; n < o.frames; ++n) {
    const FrameState state = world.frame(static_cast<double>(n) / o.fps);
    const auto start = std::chrono::steady_clock::now();
    renderer.drawAndPresent(state, o.dump_dir.empty() ? nullptr : &rgb, o.benchmark);
    endFrame(o, start, total_ms);
    if (!o.dump_dir.empty()) viper::gl_common::writePpm(dumpPath(o.dump_dir, n), o.width, o.height, rgb);
    if (oracle) writeOracleFrame(*oracle, n, state, world);
  }
  if (o.benchmark) std::cout << benchmarkLine(o, total_ms);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return programMain(
      "vk_test_scene", argc, argv, parseVkOptions,
      [](const VkSceneOptions& o) { return o.scene.help ? vkUsage() : std::string(); }, run);
}
