#include "vk_renderer.h"

#include <cstdint>
// SPIR-V generated at build time from shaders/ (cmake/programs.cmake), debug names kept.
#include "composite_frag.spv.h"
#include "composite_vert.spv.h"
#include "hud_frag.spv.h"
#include "hud_vert.spv.h"
#include "lit_frag.spv.h"
#include "rain_frag.spv.h"
#include "rain_vert.spv.h"
#include "scene_lit_vert.spv.h"
#include "scene_skinned_vert.spv.h"

#include <cstring>
#include <functional>

namespace viper {
namespace scene {
namespace vk {
namespace {

constexpr VkFormat kOffscreenFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkDeviceSize kMatrixBytes = 16 * sizeof(float);

// The HUD panel in normalised device coordinates (Vulkan: y down), two triangles; the top-left corner
// of the picture (test/scene/test_vk_scene_run.cpp leaves it out of its comparison with test_scene).
constexpr float kHudLeft = -0.95f, kHudRight = -0.55f, kHudTop = -0.95f, kHudBottom = -0.80f;
constexpr float kHudCorners[12] = {kHudLeft, kHudTop,    kHudRight, kHudTop,    kHudRight, kHudBottom,
                                   kHudLeft, kHudTop,    kHudRight, kHudBottom, kHudLeft,  kHudBottom};

template <size_t N>
ShaderCode code(const uint32_t (&words)[N]) {
  return {words, sizeof(words)};
}

VkDeviceSize alignUp(VkDeviceSize value, VkDeviceSize alignment) {
  return alignment <= 1 ? value : (value + alignment - 1) / alignment * alignment;
}

VkVertexInputAttributeDescription attribute(uint32_t location, VkFormat format, int offset_floats) {
  return {location, 0, format, static_cast<uint32_t>(offset_floats * sizeof(float))};
}

}  // namespace

Renderer::Renderer(const Context& context, const Swapchain& swapchain, const std::vector<MeshData>& meshes,
                   size_t skinned_draws, const RenderModes& modes)
    : context_(context),
      swapchain_(swapchain),
      device_(context.device()),
      modes_(modes),
      width_(swapchain.extent().width),
      height_(swapchain.extent().height),
      skinned_draws_(std::max<size_t>(skinned_draws, 1)) {
  try {
    depth_format_ = pickDepthFormat(context.physicalDevice());
    depth_ = context.createImage(width_, height_, depth_format_, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                 VK_IMAGE_ASPECT_DEPTH_BIT);
    if (modes_.offscreen)
      offscreen_ = context.createImage(width_, height_, kOffscreenFormat,
                                       VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                                       VK_IMAGE_ASPECT_COLOR_BIT);
    uploadMeshes(meshes);
    createDescriptors();
    createPipelines();
    createFramebuffers();
    createFrameObjects();
  } catch (...) {
    release();
    throw;
  }
}

Renderer::~Renderer() { release(); }

void Renderer::release() {
  vkDeviceWaitIdle(device_);
  for (VkSemaphore s : rendered_) vkDestroySemaphore(device_, s, nullptr);
  rendered_.clear();
  for (uint32_t i = 0; i < kFramesInFlight; ++i) {
    if (acquired_[i]) vkDestroySemaphore(device_, acquired_[i], nullptr);
    if (in_flight_[i]) vkDestroyFence(device_, in_flight_[i], nullptr);
    acquired_[i] = VK_NULL_HANDLE;
    in_flight_[i] = VK_NULL_HANDLE;
  }
  if (command_pool_) vkDestroyCommandPool(device_, command_pool_, nullptr);  // frees the command buffers
  command_pool_ = VK_NULL_HANDLE;
  for (VkFramebuffer f : scene_framebuffers_) vkDestroyFramebuffer(device_, f, nullptr);
  for (VkFramebuffer f : composite_framebuffers_) vkDestroyFramebuffer(device_, f, nullptr);
  scene_framebuffers_.clear();
  composite_framebuffers_.clear();
  for (VkPipeline& p : {std::ref(scene_pipelines_[0]), std::ref(scene_pipelines_[1]), std::ref(scene_pipelines_[2]),
                        std::ref(composite_pipeline_), std::ref(hud_pipeline_)}) {
    if (p) vkDestroyPipeline(device_, p, nullptr);
    p = VK_NULL_HANDLE;
  }
  for (VkRenderPass& p : {std::ref(scene_render_pass_), std::ref(composite_render_pass_)}) {
    if (p) vkDestroyRenderPass(device_, p, nullptr);
    p = VK_NULL_HANDLE;
  }
  for (VkPipelineLayout& l : {std::ref(scene_layout_), std::ref(composite_layout_), std::ref(hud_layout_)}) {
    if (l) vkDestroyPipelineLayout(device_, l, nullptr);
    l = VK_NULL_HANDLE;
  }
  if (descriptor_pool_) vkDestroyDescriptorPool(device_, descriptor_pool_, nullptr);  // frees the sets
  descriptor_pool_ = VK_NULL_HANDLE;
  scene_sets_.clear();
  for (VkDescriptorSetLayout& l : {std::ref(scene_set_layout_), std::ref(composite_set_layout_)}) {
    if (l) vkDestroyDescriptorSetLayout(device_, l, nullptr);
    l = VK_NULL_HANDLE;
  }
  if (sampler_) vkDestroySampler(device_, sampler_, nullptr);
  sampler_ = VK_NULL_HANDLE;
  for (GpuMesh& m : meshes_) {
    context_.destroy(m.vertices);
    context_.destroy(m.indices);
  }
  meshes_.clear();
  for (Buffer* b : {&hud_vertices_, &camera_, &bones_, &readback_}) context_.destroy(*b);
  context_.destroy(depth_);
  context_.destroy(offscreen_);
}

void Renderer::uploadMeshes(const std::vector<MeshData>& meshes) {
  struct Upload {
    Buffer* target;
    const void* data;
    VkDeviceSize bytes;
    VkBufferUsageFlags usage;
  };
  meshes_.resize(meshes.size());
  std::vector<Upload> uploads;
  for (size_t i = 0; i < meshes.size(); ++i) {
    meshes_[i].index_count = static_cast<uint32_t>(meshes[i].indices.size());
    uploads.push_back({&meshes_[i].vertices, meshes[i].vertices.data(), meshes[i].vertices.size() * sizeof(float),
                       VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    uploads.push_back({&meshes_[i].indices, meshes[i].indices.data(), meshes[i].indices.size() * sizeof(uint32_t),
                       VK_BUFFER_USAGE_INDEX_BUFFER_BIT});
  }
  if (modes_.offscreen)
    uploads.push_back({&hud_vertices_, kHudCorners, sizeof(kHudCorners), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});

  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  if (modes_.host_visible_buffers) {
    for (const Upload& u : uploads) {
      *u.target = context_.createBuffer(u.bytes, u.usage, host);
      std::memcpy(u.target->mapped, u.data, u.bytes);
    }
    return;
  }
  VkDeviceSize total = 0;
  for (const Upload& u : uploads) total += alignUp(u.bytes, 16);
  Buffer staging = context_.createBuffer(total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, host);
  try {
    VkDeviceSize offset = 0;
    std::vector<VkDeviceSize> offsets;
    for (const Upload& u : uploads) {
      std::memcpy(static_cast<char*>(staging.mapped) + offset, u.data, u.bytes);
      offsets.push_back(offset);
      offset += alignUp(u.bytes, 16);
      *u.target = context_.createBuffer(u.bytes, u.usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    }
    context_.submitAndWait([&](VkCommandBuffer commands) {
      for (size_t i = 0; i < uploads.size(); ++i) {
        const VkBufferCopy region{offsets[i], 0, uploads[i].bytes};
        vkCmdCopyBuffer(commands, staging.buffer, uploads[i].target->buffer, 1, &region);
      }
      VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_INDEX_READ_BIT;
      vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, 0, 1,
                           &barrier, 0, nullptr, 0, nullptr);
    });
  } catch (...) {
    context_.destroy(staging);
    throw;
  }
  context_.destroy(staging);
}

void Renderer::createDescriptors() {
  const VkPhysicalDeviceLimits& limits = context_.properties().limits;
  camera_stride_ = alignUp(2 * kMatrixBytes, limits.minUniformBufferOffsetAlignment);
  bones_stride_ = alignUp(kBoneCount * kMatrixBytes, limits.minStorageBufferOffsetAlignment);
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  camera_ = context_.createBuffer(kFramesInFlight * camera_stride_, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, host);
  bones_ = context_.createBuffer(kFramesInFlight * skinned_draws_ * bones_stride_, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                 host);
  if (modes_.readable)
    readback_ = context_.createBuffer(VkDeviceSize{width_} * height_ * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, host);

  // Set 0 of the scene: binding 0 the camera (one slot per frame in flight, chosen by the dynamic
  // offset), binding 1 the bones of one skinned draw.
  const VkDescriptorSetLayoutBinding scene_bindings[2] = {
      {0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr}};
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = 2;
  set_info.pBindings = scene_bindings;
  check(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &scene_set_layout_), "vkCreateDescriptorSetLayout");
  const VkDescriptorSetLayoutBinding composite_binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                                       VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  set_info.bindingCount = 1;
  set_info.pBindings = &composite_binding;
  check(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &composite_set_layout_), "vkCreateDescriptorSetLayout");

  // Push constants: the vertex stage's mat4 world at 0, the fragment stage's vec3 color at 64 (its
  // range to the device's limit with --full-push-constants).
  const uint32_t fragment_bytes = modes_.full_push_constants ? limits.maxPushConstantsSize - 64 : 16;
  const VkPushConstantRange push[2] = {{VK_SHADER_STAGE_VERTEX_BIT, 0, 64}, {VK_SHADER_STAGE_FRAGMENT_BIT, 64, fragment_bytes}};
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &scene_set_layout_;
  layout.pushConstantRangeCount = 2;
  layout.pPushConstantRanges = push;
  check(vkCreatePipelineLayout(device_, &layout, nullptr, &scene_layout_), "vkCreatePipelineLayout");
  layout.pSetLayouts = &composite_set_layout_;
  layout.pushConstantRangeCount = 0;
  check(vkCreatePipelineLayout(device_, &layout, nullptr, &composite_layout_), "vkCreatePipelineLayout");
  layout.setLayoutCount = 0;
  check(vkCreatePipelineLayout(device_, &layout, nullptr, &hud_layout_), "vkCreatePipelineLayout");

  const uint32_t scene_set_count = static_cast<uint32_t>(kFramesInFlight * skinned_draws_);
  const VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, scene_set_count},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, scene_set_count},
                                         {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.maxSets = scene_set_count + 1;
  pool.poolSizeCount = 3;
  pool.pPoolSizes = sizes;
  check(vkCreateDescriptorPool(device_, &pool, nullptr, &descriptor_pool_), "vkCreateDescriptorPool");

  const std::vector<VkDescriptorSetLayout> layouts(scene_set_count, scene_set_layout_);
  VkDescriptorSetAllocateInfo allocate{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = descriptor_pool_;
  allocate.descriptorSetCount = scene_set_count;
  allocate.pSetLayouts = layouts.data();
  scene_sets_.resize(scene_set_count);
  check(vkAllocateDescriptorSets(device_, &allocate, scene_sets_.data()), "vkAllocateDescriptorSets");
  for (uint32_t i = 0; i < scene_set_count; ++i) {
    const VkDescriptorBufferInfo camera{camera_.buffer, 0, 2 * kMatrixBytes};
    const VkDescriptorBufferInfo bones{bones_.buffer, i * bones_stride_, kBoneCount * kMatrixBytes};
    VkWriteDescriptorSet writes[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
    writes[0].dstSet = writes[1].dstSet = scene_sets_[i];
    writes[0].dstBinding = 0;
    writes[0].descriptorCount = 1;
    writes[0].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
    writes[0].pBufferInfo = &camera;
    writes[1].dstBinding = 1;
    writes[1].descriptorCount = 1;
    writes[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[1].pBufferInfo = &bones;
    vkUpdateDescriptorSets(device_, 2, writes, 0, nullptr);
  }

  if (!modes_.offscreen) return;
  VkSamplerCreateInfo sampler{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sampler.magFilter = sampler.minFilter = VK_FILTER_NEAREST;
  sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  check(vkCreateSampler(device_, &sampler, nullptr, &sampler_), "vkCreateSampler");
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &composite_set_layout_;
  check(vkAllocateDescriptorSets(device_, &allocate, &composite_set_), "vkAllocateDescriptorSets");
  const VkDescriptorImageInfo image{sampler_, offscreen_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = composite_set_;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  write.pImageInfo = &image;
  vkUpdateDescriptorSets(device_, 1, &write, 0, nullptr);
}

void Renderer::createPipelines() {
  const VkFormat scene_color = modes_.offscreen ? kOffscreenFormat : swapchain_.format();
  Targets scene{VK_NULL_HANDLE, scene_color, depth_format_};
  Targets composite{VK_NULL_HANDLE, swapchain_.format(), VK_FORMAT_UNDEFINED};
  if (!modes_.dynamic_rendering) {
    scene_render_pass_ = createRenderPass(
        device_, scene_color, VK_ATTACHMENT_LOAD_OP_CLEAR,
        modes_.offscreen ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : swapchain_.finalLayout(), depth_format_,
        modes_.render_pass2);
    scene.render_pass = scene_render_pass_;
    if (modes_.offscreen) {
      // The full-screen triangle covers every pixel: the old contents do not matter.
      composite_render_pass_ = createRenderPass(device_, swapchain_.format(), VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                                swapchain_.finalLayout(), VK_FORMAT_UNDEFINED, modes_.render_pass2);
      composite.render_pass = composite_render_pass_;
    }
  }

  PipelineDesc lit{code(kSceneLitVert), code(kLitFrag), 6 * sizeof(float),
                   {attribute(0, VK_FORMAT_R32G32B32_SFLOAT, 0), attribute(1, VK_FORMAT_R32G32B32_SFLOAT, 3)}};
  scene_pipelines_[static_cast<int>(ProgramKind::kLit)] = createPipeline(device_, scene_layout_, lit, scene);
  PipelineDesc skinned = lit;
  skinned.vertex = code(kSceneSkinnedVert);
  skinned.vertex_stride = 14 * sizeof(float);
  skinned.attributes.push_back(attribute(2, VK_FORMAT_R32G32B32A32_SFLOAT, 6));
  skinned.attributes.push_back(attribute(3, VK_FORMAT_R32G32B32A32_SFLOAT, 10));
  scene_pipelines_[static_cast<int>(ProgramKind::kSkinned)] = createPipeline(device_, scene_layout_, skinned, scene);
  // Rain: blended over what is behind it, never written into the depth buffer (as in test_scene).
  PipelineDesc rain{code(kRainVert), code(kRainFrag), 4 * sizeof(float),
                    {attribute(0, VK_FORMAT_R32G32B32_SFLOAT, 0), attribute(1, VK_FORMAT_R32_SFLOAT, 3)}};
  rain.depth_write = false;
  rain.blend = true;
  scene_pipelines_[static_cast<int>(ProgramKind::kRain)] = createPipeline(device_, scene_layout_, rain, scene);
  if (!modes_.offscreen) return;

  PipelineDesc full_screen{code(kCompositeVert), code(kCompositeFrag), 0, {}};
  full_screen.depth_test = full_screen.depth_write = false;
  composite_pipeline_ = createPipeline(device_, composite_layout_, full_screen, composite);
  PipelineDesc hud{code(kHudVert), code(kHudFrag), 2 * sizeof(float), {attribute(0, VK_FORMAT_R32G32_SFLOAT, 0)}};
  hud.depth_test = hud.depth_write = false;
  hud.blend = true;
  hud_pipeline_ = createPipeline(device_, hud_layout_, hud, composite);
}

void Renderer::createFramebuffers() {
  if (modes_.dynamic_rendering) return;
  // --render-pass2: imageless framebuffers, their attachments described (usage and format as the
  // images were made) and given at each vkCmdBeginRenderPass2.
  const VkImageUsageFlags swapchain_usage = swapchain_.usage();
  const VkFormat swapchain_format = swapchain_.format();
  auto describe = [&](VkImageView view, VkImageUsageFlags& usage, const VkFormat*& format) {
    if (view == depth_.view) usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, format = &depth_format_;
    else if (modes_.offscreen && view == offscreen_.view) usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, format = &kOffscreenFormat;
    else usage = swapchain_usage, format = &swapchain_format;
  };
  auto framebuffer = [&](VkRenderPass pass, std::vector<VkImageView> views) {
    VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    info.renderPass = pass;
    info.attachmentCount = static_cast<uint32_t>(views.size());
    info.pAttachments = views.data();
    info.width = width_;
    info.height = height_;
    info.layers = 1;
    std::vector<VkFramebufferAttachmentImageInfo> images;
    VkFramebufferAttachmentsCreateInfo described{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO};
    if (modes_.render_pass2) {
      for (VkImageView view : views) {
        VkFramebufferAttachmentImageInfo image{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENT_IMAGE_INFO};
        describe(view, image.usage, image.pViewFormats);
        image.width = width_, image.height = height_, image.layerCount = 1, image.viewFormatCount = 1;
        images.push_back(image);
      }
      described.attachmentImageInfoCount = static_cast<uint32_t>(images.size());
      described.pAttachmentImageInfos = images.data();
      info.pNext = &described;
      info.flags = VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT;
      info.pAttachments = nullptr;
    }
    VkFramebuffer f = VK_NULL_HANDLE;
    check(vkCreateFramebuffer(device_, &info, nullptr, &f), "vkCreateFramebuffer");
    return f;
  };
  if (modes_.offscreen) {
    scene_framebuffers_.push_back(framebuffer(scene_render_pass_, {offscreen_.view, depth_.view}));
    for (size_t i = 0; i < swapchain_.imageCount(); ++i)
      composite_framebuffers_.push_back(framebuffer(composite_render_pass_, {swapchain_.view(i)}));
  } else {
    for (size_t i = 0; i < swapchain_.imageCount(); ++i)
      scene_framebuffers_.push_back(framebuffer(scene_render_pass_, {swapchain_.view(i), depth_.view}));
  }
}

void Renderer::createFrameObjects() {
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = context_.queueFamily();
  check(vkCreateCommandPool(device_, &pool, nullptr, &command_pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = command_pool_;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = kFramesInFlight;
  check(vkAllocateCommandBuffers(device_, &allocate, command_buffers_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  for (uint32_t i = 0; i < kFramesInFlight; ++i)
    check(vkCreateFence(device_, &fence, nullptr, &in_flight_[i]), "vkCreateFence");
  // Headless, nothing is acquired or presented: the frame's fence is all the synchronisation there is.
  rendered_.resize(swapchain_.imageCount(), VK_NULL_HANDLE);
  if (swapchain_.headless()) return;
  const VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  for (VkSemaphore& s : acquired_) check(vkCreateSemaphore(device_, &semaphore, nullptr, &s), "vkCreateSemaphore");
  for (VkSemaphore& s : rendered_) check(vkCreateSemaphore(device_, &semaphore, nullptr, &s), "vkCreateSemaphore");
}

}  // namespace vk
}  // namespace scene
}  // namespace viper
