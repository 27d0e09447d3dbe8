// Renderer, per frame: the frame's uniform data, its command buffer, submission and presentation.
#include "vk_renderer.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace viper {
namespace scene {
namespace vk {
namespace {

constexpr VkClearColorValue kSky = {{0.53f, 0.70f, 0.90f, 1.0f}};
constexpr VkPipelineStageFlags kDepthStages =
    VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;

// OpenGL clip space (y up, z in [-1, 1]) -> Vulkan's (y down, z in [0, 1]).
Eigen::Matrix4f vulkanClipFromGl() {
  Eigen::Matrix4f c;
  c << 1, 0, 0, 0,
       0, -1, 0, 0,
       0, 0, 0.5f, 0.5f,
       0, 0, 0, 1;
  return c;
}

void imageBarrier(VkCommandBuffer commands, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                  VkImageLayout to, VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                  VkPipelineStageFlags dst_stages, VkAccessFlags dst_access) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {aspect, 0, 1, 0, 1};
  vkCmdPipelineBarrier(commands, src_stages, dst_stages, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

}  // namespace

void Renderer::drawAndPresent(const FrameState& frame, std::vector<uint8_t>* rgb, bool wait) {
  const uint32_t slot = static_cast<uint32_t>(frame_count_++ % kFramesInFlight);
  check(vkWaitForFences(device_, 1, &in_flight_[slot], VK_TRUE, UINT64_MAX), "vkWaitForFences");
  writeFrameData(slot, frame);
  const uint32_t image = swapchain_.acquire(acquired_[slot]);
  check(vkResetFences(device_, 1, &in_flight_[slot]), "vkResetFences");

  VkCommandBuffer commands = command_buffers_[slot];
  check(vkResetCommandBuffer(commands, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(commands, &begin), "vkBeginCommandBuffer");
  record(commands, slot, image, frame);
  check(vkEndCommandBuffer(commands), "vkEndCommandBuffer");

  // Headless, no semaphores (there is no presentation engine to wait for or to signal): only the fence.
  const bool presents = !swapchain_.headless();
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands;
  if (presents) {
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &acquired_[slot];
    submit.pWaitDstStageMask = &wait_stage;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &rendered_[image];
  }
  if (modes_.render_pass2) {
    // synchronization2's submission: the same waits and signals.
    VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    wait.semaphore = acquired_[slot];
    wait.stageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    signal.semaphore = rendered_[image];
    signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    VkCommandBufferSubmitInfo buffer{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    buffer.commandBuffer = commands;
    VkSubmitInfo2 submit2{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit2.commandBufferInfoCount = 1;
    submit2.pCommandBufferInfos = &buffer;
    if (presents) {
      submit2.waitSemaphoreInfoCount = 1;
      submit2.pWaitSemaphoreInfos = &wait;
      submit2.signalSemaphoreInfoCount = 1;
      submit2.pSignalSemaphoreInfos = &signal;
    }
    check(vkQueueSubmit2(context_.queue(), 1, &submit2, in_flight_[slot]), "vkQueueSubmit2");
  } else {
    check(vkQueueSubmit(context_.queue(), 1, &submit, in_flight_[slot]), "vkQueueSubmit");
  }
  // Like test_scene, a dump is read (and a benchmark frame finished) before the image is presented.
  if (rgb || wait) check(vkWaitForFences(device_, 1, &in_flight_[slot], VK_TRUE, UINT64_MAX), "vkWaitForFences");
  if (rgb) {
    const uint8_t* bgra = static_cast<const uint8_t*>(readback_.mapped);
    const bool swap = swapchain_.bgr();
    rgb->resize(size_t{width_} * height_ * 3);
    for (size_t p = 0; p < size_t{width_} * height_; ++p) {
      (*rgb)[3 * p] = bgra[4 * p + (swap ? 2 : 0)];
      (*rgb)[3 * p + 1] = bgra[4 * p + 1];
      (*rgb)[3 * p + 2] = bgra[4 * p + (swap ? 0 : 2)];
    }
  }
  swapchain_.present(image, rendered_[image], in_flight_[slot]);
}

void Renderer::writeFrameData(uint32_t slot, const FrameState& frame) {
  char* camera = static_cast<char*>(camera_.mapped) + slot * camera_stride_;
  const Eigen::Matrix4f projection = vulkanClipFromGl() * frame.projection;
  std::memcpy(camera, frame.view.data(), 64);
  std::memcpy(camera + 64, projection.data(), 64);
  size_t k = 0;
  for (const DrawItem& item : frame.draws) {
    if (item.program != ProgramKind::kSkinned) continue;
    if (k == skinned_draws_)
      throw std::runtime_error("frame at " + std::to_string(frame.time_s) + " s has more than " +
                               std::to_string(skinned_draws_) + " skinned draws");
    if (item.bones.size() != static_cast<size_t>(kBoneCount))
      throw std::runtime_error("a skinned draw has " + std::to_string(item.bones.size()) + " bones, not " +
                               std::to_string(kBoneCount));
    char* bones = static_cast<char*>(bones_.mapped) + (slot * skinned_draws_ + k++) * bones_stride_;
    for (size_t b = 0; b < item.bones.size(); ++b) std::memcpy(bones + 64 * b, item.bones[b].data(), 64);
  }
}

void Renderer::record(VkCommandBuffer commands, uint32_t slot, uint32_t image, const FrameState& frame) {
  const VkViewport viewport{0, 0, static_cast<float>(width_), static_cast<float>(height_), 0, 1};
  const VkRect2D scissor{{0, 0}, {width_, height_}};
  vkCmdSetViewport(commands, 0, 1, &viewport);
  vkCmdSetScissor(commands, 0, 1, &scissor);
  const Pass scene = scenePass(image);
  beginPass(commands, scene);
  recordScene(commands, slot, frame);
  endPass(commands, scene);
  if (modes_.offscreen) {
    const Pass composite = compositePass(image);
    beginPass(commands, composite);
    recordComposite(commands);
    endPass(commands, composite);
  }
  if (modes_.readable) recordReadback(commands, image);
}

void Renderer::recordScene(VkCommandBuffer commands, uint32_t slot, const FrameState& frame) {
  const uint32_t camera_offset = static_cast<uint32_t>(slot * camera_stride_);
  VkPipeline current = VK_NULL_HANDLE;
  size_t skinned = 0;
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    const DrawItem& item = frame.draws[i];
    const VkPipeline pipeline = scene_pipelines_[static_cast<int>(item.program)];
    if (pipeline != current) {
      vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
      current = pipeline;
    }
    // Set 0 once per frame, and again for each skinned draw (its own bones).
    const bool is_skinned = item.program == ProgramKind::kSkinned;
    if (i == 0 || is_skinned) {
      const VkDescriptorSet set = scene_sets_[slot * skinned_draws_ + (is_skinned ? skinned++ : 0)];
      vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, scene_layout_, 0, 1, &set, 1, &camera_offset);
    }
    vkCmdPushConstants(commands, scene_layout_, VK_SHADER_STAGE_VERTEX_BIT, 0, 64, item.world.data());
    if (item.program != ProgramKind::kRain)
      vkCmdPushConstants(commands, scene_layout_, VK_SHADER_STAGE_FRAGMENT_BIT, 64, 12, item.color.data());
    const GpuMesh& mesh = meshes_.at(item.mesh);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(commands, 0, 1, &mesh.vertices.buffer, &offset);
    vkCmdBindIndexBuffer(commands, mesh.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(commands, mesh.index_count, 1, 0, 0, 0);
  }
}

void Renderer::recordComposite(VkCommandBuffer commands) {
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, composite_pipeline_);
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, composite_layout_, 0, 1, &composite_set_, 0,
                          nullptr);
  vkCmdDraw(commands, 3, 1, 0, 0);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, hud_pipeline_);
  const VkDeviceSize offset = 0;
  vkCmdBindVertexBuffers(commands, 0, 1, &hud_vertices_.buffer, &offset);
  vkCmdDraw(commands, 6, 1, 0, 0);
}

void Renderer::recordReadback(VkCommandBuffer commands, uint32_t image) {
  // The pass that wrote the image made its writes available, up to the transfer stage, and left
  // it in the swapchain's final layout (PRESENT_SRC, or headless already TRANSFER_SRC); this barrier
  // chains on at that stage and makes them visible to the copy.
  const VkImageLayout final_layout = swapchain_.finalLayout();
  imageBarrier(commands, swapchain_.image(image), VK_IMAGE_ASPECT_COLOR_BIT, final_layout,
               VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_READ_BIT);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width_, height_, 1};
  vkCmdCopyImageToBuffer(commands, swapchain_.image(image), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer, 1,
                         &region);
  if (final_layout != VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)
    imageBarrier(commands, swapchain_.image(image), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 final_layout, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0);
  VkBufferMemoryBarrier host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  host.srcQueueFamilyIndex = host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  host.buffer = readback_.buffer;
  host.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &host,
                       0, nullptr);
}

Renderer::Pass Renderer::scenePass(uint32_t image) const {
  Pass p;
  p.render_pass = scene_render_pass_;
  p.depth = true;
  p.clear = true;
  p.sampled_after = modes_.offscreen;
  if (modes_.offscreen) {
    p.color_image = offscreen_.image;
    p.color_view = offscreen_.view;
  } else {
    p.color_image = swapchain_.image(image);
    p.color_view = swapchain_.view(image);
  }
  if (!scene_framebuffers_.empty()) p.framebuffer = scene_framebuffers_[modes_.offscreen ? 0 : image];
  return p;
}

Renderer::Pass Renderer::compositePass(uint32_t image) const {
  Pass p;
  p.render_pass = composite_render_pass_;
  p.color_image = swapchain_.image(image);
  p.color_view = swapchain_.view(image);
  if (!composite_framebuffers_.empty()) p.framebuffer = composite_framebuffers_[image];
  return p;
}

void Renderer::beginPass(VkCommandBuffer commands, const Pass& pass) {
  const VkRect2D area{{0, 0}, {width_, height_}};
  VkClearValue clears[2];
  clears[0].color = kSky;
  clears[1].depthStencil = {1.0f, 0};
  if (pass.render_pass) {
    VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    begin.renderPass = pass.render_pass;
    begin.framebuffer = pass.framebuffer;
    begin.renderArea = area;
    begin.clearValueCount = pass.depth ? 2 : pass.clear ? 1 : 0;
    begin.pClearValues = begin.clearValueCount ? clears : nullptr;
    if (!modes_.render_pass2) {
      vkCmdBeginRenderPass(commands, &begin, VK_SUBPASS_CONTENTS_INLINE);
      return;
    }
    // Imageless framebuffer: the views are given here.
    const VkImageView views[2] = {pass.color_view, depth_.view};
    VkRenderPassAttachmentBeginInfo attachments{VK_STRUCTURE_TYPE_RENDER_PASS_ATTACHMENT_BEGIN_INFO};
    attachments.attachmentCount = pass.depth ? 2 : 1;
    attachments.pAttachments = views;
    begin.pNext = &attachments;
    VkSubpassBeginInfo subpass{VK_STRUCTURE_TYPE_SUBPASS_BEGIN_INFO};
    subpass.contents = VK_SUBPASS_CONTENTS_INLINE;
    vkCmdBeginRenderPass2(commands, &begin, &subpass);
    return;
  }
  // Dynamic rendering: the layout transitions and waits a render pass would do.
  imageBarrier(commands, pass.color_image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
               VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = pass.color_view;
  color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.loadOp = pass.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.clearValue = clears[0];
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = depth_.view;
  depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  depth.clearValue = clears[1];
  VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
  info.renderArea = area;
  info.layerCount = 1;
  info.colorAttachmentCount = 1;
  info.pColorAttachments = &color;
  if (pass.depth) {
    const VkImageAspectFlags aspects = depthAspects(depth_format_);
    imageBarrier(commands, depth_.image, aspects, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, kDepthStages,
                 VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, kDepthStages,
                 VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    info.pDepthAttachment = &depth;
    if (aspects & VK_IMAGE_ASPECT_STENCIL_BIT) info.pStencilAttachment = &depth;
  }
  context_.cmdBeginRendering(commands, &info);
}

void Renderer::endPass(VkCommandBuffer commands, const Pass& pass) {
  if (pass.render_pass) {
    const VkSubpassEndInfo end{VK_STRUCTURE_TYPE_SUBPASS_END_INFO};
    if (modes_.render_pass2) vkCmdEndRenderPass2(commands, &end);
    else vkCmdEndRenderPass(commands);
    return;
  }
  context_.cmdEndRendering(commands);
  // As the render pass's outgoing dependency: to sampling, or to presentation (headless, to the
  // transfer layout) and the dump's copy, whose barrier makes the writes visible to it.
  imageBarrier(commands, pass.color_image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               pass.sampled_after ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : swapchain_.finalLayout(),
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               pass.sampled_after ? VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT : VK_PIPELINE_STAGE_TRANSFER_BIT,
               pass.sampled_after ? VK_ACCESS_SHADER_READ_BIT : 0);
}

}  // namespace vk
}  // namespace scene
}  // namespace viper
