// Command line of vk_test_scene: test_scene's options (less --gl-loader) and the Vulkan ways of drawing.
#pragma once

#include "scene/options.h"

#include <string>
#include <vector>

namespace viper {
namespace scene {

/// test_scene's options plus how vk_test_scene draws (all false: render pass, staging upload, a window).
struct VkSceneOptions {
  SceneOptions scene;
  bool dynamic_rendering = false;     ///< --dynamic-rendering
  bool offscreen = false;             ///< --offscreen
  bool host_visible_buffers = false;  ///< --host-visible-buffers
  bool full_push_constants = false;   ///< --full-push-constants
  bool render_pass2 = false;          ///< --render-pass2
  bool headless = false;              ///< --headless
};

/// Parses argv[1..] as parseOptions does, plus the flags above. Throws OptionsError as
/// parseOptions does, and for --gl-loader (an OpenGL option) or a flag given a value.
VkSceneOptions parseVkOptions(const std::vector<std::string>& args);

/// The --help text of vk_test_scene.
std::string vkUsage();

}  // namespace scene
}  // namespace viper
