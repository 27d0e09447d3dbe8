// Render passes and graphics pipelines of vk_test_scene, built from small descriptions.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace viper {
namespace scene {
namespace vk {

/// Where a pipeline draws: subpass 0 of `render_pass`, or (render_pass null) dynamic rendering into
/// attachments of these formats.
struct Targets {
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VkFormat color = VK_FORMAT_UNDEFINED;
  VkFormat depth = VK_FORMAT_UNDEFINED;  ///< UNDEFINED: no depth attachment
};

/// SPIR-V words of one shader stage.
struct ShaderCode {
  const uint32_t* words = nullptr;
  size_t bytes = 0;
};

/// How a pipeline draws: triangle lists, no culling, viewport and scissor set per command buffer.
struct PipelineDesc {
  ShaderCode vertex, fragment;
  uint32_t vertex_stride = 0;  ///< bytes per vertex of binding 0; 0: no vertex buffer
  std::vector<VkVertexInputAttributeDescription> attributes;  ///< of binding 0
  bool depth_test = true;
  bool depth_write = true;
  bool blend = false;  ///< src alpha over (one minus src alpha), as test_scene's rain
};

/// Creates the pipeline; throws VulkanError.
VkPipeline createPipeline(VkDevice device, VkPipelineLayout layout, const PipelineDesc& desc, const Targets& targets);

/// A single-subpass render pass: one colour attachment (loaded with `color_load`, stored, left in
/// `final_layout`) and, unless `depth` is UNDEFINED, a depth attachment that is cleared and not
/// stored. Its external dependencies wait for earlier attachment writes and sampling of the colour
/// image, and make the colour writes visible to sampling (SHADER_READ_ONLY_OPTIMAL) or available up
/// to the transfer stage (where a frame dump's barrier chains on). `render_pass2`: made with
/// vkCreateRenderPass2 from Vulkan 1.2's structures.
VkRenderPass createRenderPass(VkDevice device, VkFormat color, VkAttachmentLoadOp color_load, VkImageLayout final_layout,
                              VkFormat depth, bool render_pass2 = false);

/// D32_SFLOAT if the device can render depth into it, else a 24-bit depth format.
VkFormat pickDepthFormat(VkPhysicalDevice device);

/// The aspects of a depth format's image (depth, and stencil for combined formats).
VkImageAspectFlags depthAspects(VkFormat format);

}  // namespace vk
}  // namespace scene
}  // namespace viper
