// Draws test_scene's frames with Vulkan into the window's swapchain (or, headless, its stand-in, a
// ring of plain images), the ways engines do: the world matrix in push constants, the camera in a
// uniform buffer at a dynamic offset, bones in a storage buffer, meshes in device-local buffers
// filled through a staging buffer.
#pragma once

#include "vk_context.h"
#include "vk_pipelines.h"

#include "scene/world.h"

#include <cstdint>
#include <vector>

namespace viper {
namespace scene {
namespace vk {

/// How the renderer draws; every combination is valid.
struct RenderModes {
  bool dynamic_rendering = false;     ///< vkCmdBeginRendering instead of render passes and framebuffers
  bool offscreen = false;             ///< scene into an offscreen target, composited with a HUD on top
  bool host_visible_buffers = false;  ///< meshes in host-visible buffers written directly (no staging)
  bool full_push_constants = false;   ///< the fragment push-constant range reaches maxPushConstantsSize
  bool render_pass2 = false;          ///< vkCreateRenderPass2, imageless framebuffers, vkQueueSubmit2
  bool readable = false;              ///< copy each presented image back (the swapchain must be readable)
};

/// Frames in flight: slots of the camera uniform buffer, bone buffer and command buffers.
constexpr uint32_t kFramesInFlight = 2;

/// Owns every Vulkan object of the scene (buffers, images, pipelines, descriptor sets, command
/// buffers, synchronisation) and draws one DrawItem per vkCmdDrawIndexed, in order.
class Renderer {
 public:
  /// Uploads `meshes` and builds the pipelines. `skinned_draws` is the most skinned draws a frame
  /// has (one bone slot and descriptor set each). Throws VulkanError / std::runtime_error.
  Renderer(const Context& context, const Swapchain& swapchain, const std::vector<MeshData>& meshes,
           size_t skinned_draws, const RenderModes& modes);
  /// Waits for the device to be idle, then destroys everything.
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Renders `frame` into the next swapchain image and presents it (headless: waits for it). With
  /// `rgb`, fills it with the image as presented (rgb8, top row first); with `rgb` or `wait`, returns
  /// only after the GPU has finished the frame. Throws VulkanError, or std::runtime_error if the frame has more skinned
  /// draws than the constructor was told.
  void drawAndPresent(const FrameState& frame, std::vector<uint8_t>* rgb, bool wait);

 private:
  struct GpuMesh {
    Buffer vertices, indices;
    uint32_t index_count = 0;
  };
  // One colour attachment (and maybe the depth image) drawn in one render pass instance.
  struct Pass {
    VkRenderPass render_pass = VK_NULL_HANDLE;  // null with dynamic rendering
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    VkImage color_image = VK_NULL_HANDLE;
    VkImageView color_view = VK_NULL_HANDLE;
    bool depth = false;          // clears and uses depth_
    bool clear = false;          // clears the colour to the sky, else does not care
    bool sampled_after = false;  // ends in SHADER_READ_ONLY_OPTIMAL, else the swapchain's finalLayout()
  };

  void release();
  void uploadMeshes(const std::vector<MeshData>& meshes);
  void createDescriptors();
  void createPipelines();
  void createFramebuffers();
  void createFrameObjects();
  void writeFrameData(uint32_t slot, const FrameState& frame);
  void record(VkCommandBuffer commands, uint32_t slot, uint32_t image, const FrameState& frame);
  void recordScene(VkCommandBuffer commands, uint32_t slot, const FrameState& frame);
  void recordComposite(VkCommandBuffer commands);
  void recordReadback(VkCommandBuffer commands, uint32_t image);
  void beginPass(VkCommandBuffer commands, const Pass& pass);
  void endPass(VkCommandBuffer commands, const Pass& pass);
  Pass scenePass(uint32_t image) const;
  Pass compositePass(uint32_t image) const;

  const Context& context_;
  const Swapchain& swapchain_;
  VkDevice device_;
  RenderModes modes_;
  uint32_t width_, height_;
  size_t skinned_draws_;
  VkDeviceSize camera_stride_ = 0, bones_stride_ = 0;

  std::vector<GpuMesh> meshes_;
  Buffer hud_vertices_;
  Buffer camera_, bones_, readback_;
  VkFormat depth_format_ = VK_FORMAT_UNDEFINED;
  Image depth_, offscreen_;
  VkSampler sampler_ = VK_NULL_HANDLE;

  VkDescriptorSetLayout scene_set_layout_ = VK_NULL_HANDLE, composite_set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout scene_layout_ = VK_NULL_HANDLE, composite_layout_ = VK_NULL_HANDLE, hud_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> scene_sets_;  // [slot * skinned_draws_ + k]
  VkDescriptorSet composite_set_ = VK_NULL_HANDLE;

  VkRenderPass scene_render_pass_ = VK_NULL_HANDLE, composite_render_pass_ = VK_NULL_HANDLE;
  std::vector<VkFramebuffer> scene_framebuffers_, composite_framebuffers_;
  VkPipeline scene_pipelines_[3] = {VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE};  // by ProgramKind
  VkPipeline composite_pipeline_ = VK_NULL_HANDLE, hud_pipeline_ = VK_NULL_HANDLE;

  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer command_buffers_[kFramesInFlight] = {};
  VkFence in_flight_[kFramesInFlight] = {};
  VkSemaphore acquired_[kFramesInFlight] = {};  // null when headless, as rendered_'s
  std::vector<VkSemaphore> rendered_;  // per swapchain image: signalled by the frame's submit, waited by its present
  uint64_t frame_count_ = 0;
};

}  // namespace vk
}  // namespace scene
}  // namespace viper
