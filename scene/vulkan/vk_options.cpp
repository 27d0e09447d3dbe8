#include "vk_options.h"

namespace viper {
namespace scene {

VkSceneOptions parseVkOptions(const std::vector<std::string>& args) {
  VkSceneOptions o;
  std::vector<std::string> shared;
  for (const std::string& arg : args) {
    const std::string name = arg.substr(0, arg.find('='));
    bool* flag = name == "--dynamic-rendering"      ? &o.dynamic_rendering
                 : name == "--offscreen"            ? &o.offscreen
                 : name == "--host-visible-buffers" ? &o.host_visible_buffers
                 : name == "--full-push-constants"  ? &o.full_push_constants
                 : name == "--render-pass2"         ? &o.render_pass2
                 : name == "--headless"             ? &o.headless
                                                    : nullptr;
    if (flag) {
      if (name != arg) throw OptionsError(name + " takes no value");
      *flag = true;
    } else if (name == "--gl-loader") {
      throw OptionsError("--gl-loader is test_scene's OpenGL option; vk_test_scene draws with Vulkan");
    } else {
      shared.push_back(arg);
    }
  }
  o.scene = parseOptions(shared);
  if (o.render_pass2 && o.dynamic_rendering) throw OptionsError("--render-pass2 and --dynamic-rendering exclude each other");
  return o;
}

std::string vkUsage() {
  return "Usage: vk_test_scene [options]\n"
         "Renders test_scene's scene with Vulkan 1.2/1.3 into an X window's swapchain ($DISPLAY, e.g. Xvfb),\n"
         "one vkQueuePresentKHR per frame (--headless: into images of its own, nothing presented): world\n"
         "matrices in push constants, the camera in a uniform buffer at a dynamic offset, bones in a\n"
         "storage buffer. Knows nothing of capture; its oracle equals test_scene's for the same options.\n" +
         sharedOptionsUsage() +
         "  --dynamic-rendering vkCmdBeginRendering (Vulkan 1.3 / VK_KHR_dynamic_rendering), not render passes\n"
         "  --offscreen         draw the scene into an offscreen target, then onto the swapchain image with\n"
         "                      a full-screen triangle and a HUD panel on top (top-left corner)\n"
         "  --host-visible-buffers  meshes in host-visible buffers (default: device-local, staging copy)\n"
         "  --full-push-constants   the fragment stage's push-constant range reaches the device's limit\n"
         "                      (maxPushConstantsSize), as SuperTuxKart's does: no room left past it\n"
         "  --render-pass2      Vulkan 1.2/1.3's structures: render passes made with vkCreateRenderPass2\n"
         "                      and begun with vkCmdBeginRenderPass2, imageless framebuffers, vkQueueSubmit2\n"
         "                      (needs Vulkan 1.3; not with --dynamic-rendering)\n"
         "  --headless          no X connection, window, surface or swapchain: each frame is drawn into an\n"
         "                      image of its own (R8G8B8A8_UNORM, a ring of two) and nothing is presented,\n"
         "                      as an offscreen renderer does; combines with every flag above\n"
         "  --help              this text\n"
         "Exit codes: 0 ok, 1 runtime failure (no X display without --headless, no Vulkan device, Vulkan\n"
         "error, file), 2 bad command line.\n";
}

}  // namespace scene
}  // namespace viper
