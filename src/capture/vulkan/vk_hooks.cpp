// The Vulkan layer's entry points: instance and device creation (dispatch chains), the objects it
// follows or changes (capture_layer.h says what it changes), and command recording.
#include "capture_layer.h"

#include "viper/capture/content_key.h"

#include <algorithm>
#include <cstring>
#include <tuple>
#include <vector>

#define VIPER_VK_EXPORT extern "C" __attribute__((visibility("default")))

namespace viper {
namespace capture {
namespace vulkan {
namespace {

using Device = Layer::Device;
using Lock = std::lock_guard<std::mutex>;

Layer& L() { return Layer::get(); }
template <typename T>
Device& dev(T handle) {
  return *L().device(dispatchKey(handle));
}

constexpr VkFormat kIdFormat = VK_FORMAT_R32G32B32A32_UINT;

bool isReadableColorFormat(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_SRGB;
}

bool isDepthFormat(VkFormat f) {
  return f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_X8_D24_UNORM_PACK32 || f == VK_FORMAT_D32_SFLOAT ||
         f == VK_FORMAT_D16_UNORM_S8_UINT || f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

template <typename T>
const T* findInChain(const void* next, VkStructureType type) {
  for (auto* s = static_cast<const VkBaseInStructure*>(next); s; s = s->pNext)
    if (s->sType == type) return reinterpret_cast<const T*>(s);
  return nullptr;
}

// A destroyed object is forgotten (under the lock) before the driver destroys it.
template <typename Handle, typename... Maps>
void forget(Handle handle, Maps&... maps) {
  Lock lock(L().mutex());
  (maps.erase(handle), ...);
}

// ---------------------------------------------------------------------------------------------
// Instance and device.

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo* info, const VkAllocationCallbacks* alloc,
                                              VkInstance* out) {
  auto* link = const_cast<VkLayerInstanceCreateInfo*>(
      findInChain<VkLayerInstanceCreateInfo>(info->pNext, VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO));
  while (link && link->function != VK_LAYER_LINK_INFO)
    link = const_cast<VkLayerInstanceCreateInfo*>(
        findInChain<VkLayerInstanceCreateInfo>(link->pNext, VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO));
  if (!link) return VK_ERROR_INITIALIZATION_FAILED;
  PFN_vkGetInstanceProcAddr gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  auto create = reinterpret_cast<PFN_vkCreateInstance>(gipa(VK_NULL_HANDLE, "vkCreateInstance"));
  const VkResult r = create(info, alloc, out);
  if (r == VK_SUCCESS) L().addInstance(*out, gipa);
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyInstance(VkInstance instance, const VkAllocationCallbacks* alloc) {
  InstanceData* d = L().instance(dispatchKey(instance));
  PFN_vkDestroyInstance destroy = d ? d->DestroyInstance : nullptr;
  L().removeInstance(instance);
  if (destroy) destroy(instance, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice physical, const VkDeviceCreateInfo* info,
                                            const VkAllocationCallbacks* alloc, VkDevice* out) {
  auto chain = [&](VkLayerFunction f) {
    auto* c = const_cast<VkLayerDeviceCreateInfo*>(
        findInChain<VkLayerDeviceCreateInfo>(info->pNext, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO));
    while (c && c->function != f)
      c = const_cast<VkLayerDeviceCreateInfo*>(
          findInChain<VkLayerDeviceCreateInfo>(c->pNext, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO));
    return c;
  };
  VkLayerDeviceCreateInfo* link = chain(VK_LAYER_LINK_INFO);
  VkLayerDeviceCreateInfo* loader_data = chain(VK_LOADER_DATA_CALLBACK);
  if (!link) return VK_ERROR_INITIALIZATION_FAILED;
  PFN_vkGetInstanceProcAddr gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  PFN_vkGetDeviceProcAddr gdpa = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  InstanceData* inst = L().instance(dispatchKey(physical));
  auto create = reinterpret_cast<PFN_vkCreateDevice>(gipa(inst ? inst->instance : VK_NULL_HANDLE, "vkCreateDevice"));

  // gl_PrimitiveID in fragment shaders needs the geometryShader feature, and the id attachment's own
  // blend state independentBlend: both enabled where the device has them (the program's own
  // features stay as it asked, its structures as it made them).
  VkDeviceCreateInfo copy = *info;
  VkPhysicalDeviceFeatures features{};
  VkPhysicalDeviceFeatures supported{};
  if (inst) inst->GetPhysicalDeviceFeatures(physical, &supported);
  auto* features2 = const_cast<VkPhysicalDeviceFeatures2*>(
      findInChain<VkPhysicalDeviceFeatures2>(info->pNext, VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2));
  VkPhysicalDeviceFeatures program_features{};
  const bool primitive_id = L().capturing() && supported.geometryShader && supported.independentBlend;
  if (primitive_id) {
    if (features2) {
      program_features = features2->features;
      features2->features.geometryShader = VK_TRUE;  // restored below
      features2->features.independentBlend = VK_TRUE;
    } else {
      if (info->pEnabledFeatures) features = *info->pEnabledFeatures;
      features.geometryShader = VK_TRUE;
      features.independentBlend = VK_TRUE;
      copy.pEnabledFeatures = &features;
    }
  }
  const VkResult r = create(physical, &copy, alloc, out);
  if (features2 && primitive_id) features2->features = program_features;
  if (r != VK_SUCCESS) return r;
  Device* d = L().addDevice(physical, *out, gdpa, loader_data ? loader_data->u.pfnSetDeviceLoaderData : nullptr);
  d->primitive_id = primitive_id;
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice device, const VkAllocationCallbacks* alloc) {
  PFN_vkDestroyDevice destroy = nullptr;
  if (Device* d = L().device(dispatchKey(device))) {
    destroy = d->vk.DestroyDevice;
    L().removeDevice(device);
  }
  if (destroy) destroy(device, alloc);
}

VKAPI_ATTR void VKAPI_CALL GetDeviceQueue(VkDevice device, uint32_t family, uint32_t index, VkQueue* queue) {
  Device& d = dev(device);
  d.vk.GetDeviceQueue(device, family, index, queue);
  Lock lock(L().mutex());
  d.queue_families[*queue] = family;
}

VKAPI_ATTR void VKAPI_CALL GetDeviceQueue2(VkDevice device, const VkDeviceQueueInfo2* info, VkQueue* queue) {
  Device& d = dev(device);
  d.vk.GetDeviceQueue2(device, info, queue);
  Lock lock(L().mutex());
  d.queue_families[*queue] = info->queueFamilyIndex;
}

// ---------------------------------------------------------------------------------------------
// Memory, buffers, images.

VKAPI_ATTR VkResult VKAPI_CALL AllocateMemory(VkDevice device, const VkMemoryAllocateInfo* info,
                                              const VkAllocationCallbacks* alloc, VkDeviceMemory* out) {
  Device& d = dev(device);
  const VkResult r = d.vk.AllocateMemory(device, info, alloc, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    MemoryInfo m;
    m.size = info->allocationSize;
    m.type = info->memoryTypeIndex;
    const VkMemoryPropertyFlags flags = d.memory_properties.memoryTypes[m.type].propertyFlags;
    m.host_visible = flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
    m.coherent = flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    d.memories[*out] = m;
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL FreeMemory(VkDevice device, VkDeviceMemory memory, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(memory, d.memories);
  d.vk.FreeMemory(device, memory, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL MapMemory(VkDevice device, VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size,
                                         VkMemoryMapFlags flags, void** data) {
  Device& d = dev(device);
  Lock lock(L().mutex());  // the layer maps memory the program has not mapped, under the same lock
  const VkResult r = d.vk.MapMemory(device, memory, offset, size, flags, data);
  if (r == VK_SUCCESS) {
    auto m = d.memories.find(memory);
    if (m != d.memories.end()) m->second.program_mapping = *data, m->second.program_offset = offset;
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL UnmapMemory(VkDevice device, VkDeviceMemory memory) {
  Device& d = dev(device);
  Lock lock(L().mutex());
  auto m = d.memories.find(memory);
  if (m != d.memories.end()) m->second.program_mapping = nullptr;
  d.vk.UnmapMemory(device, memory);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateBuffer(VkDevice device, const VkBufferCreateInfo* info,
                                            const VkAllocationCallbacks* alloc, VkBuffer* out) {
  Device& d = dev(device);
  const VkResult r = d.vk.CreateBuffer(device, info, alloc, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    d.buffers[*out].size = info->size;
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyBuffer(VkDevice device, VkBuffer buffer, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(buffer, d.buffers, d.shadows);
  d.vk.DestroyBuffer(device, buffer, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory(VkDevice device, VkBuffer buffer, VkDeviceMemory memory,
                                                VkDeviceSize offset) {
  Device& d = dev(device);
  const VkResult r = d.vk.BindBufferMemory(device, buffer, memory, offset);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    d.buffers[buffer].memory = memory;
    d.buffers[buffer].memory_offset = offset;
  }
  return r;
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory2(VkDevice device, uint32_t count, const VkBindBufferMemoryInfo* infos) {
  Device& d = dev(device);
  const VkResult r = d.vk.BindBufferMemory2(device, count, infos);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    for (uint32_t i = 0; i < count; ++i) {
      d.buffers[infos[i].buffer].memory = infos[i].memory;
      d.buffers[infos[i].buffer].memory_offset = infos[i].memoryOffset;
    }
  }
  return r;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateImage(VkDevice device, const VkImageCreateInfo* info,
                                           const VkAllocationCallbacks* alloc, VkImage* out) {
  Device& d = dev(device);
  // Depth attachments are read back at the end of the scene's render pass.
  VkImageCreateInfo copy = *info;
  const bool depth = L().capturing() && isDepthFormat(info->format) &&
                     (info->usage & VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) &&
                     info->samples == VK_SAMPLE_COUNT_1_BIT;
  if (depth) copy.usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  // On a device without a swapchain (a program that never presents), the frame's colour is read
  // from the scene pass's colour attachment: 8-bit RGBA colour attachments can be copied from.
  if (L().capturing() && isReadableColorFormat(info->format) && (info->usage & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) &&
      info->samples == VK_SAMPLE_COUNT_1_BIT) {
    Lock lock(L().mutex());
    if (d.swapchains.empty()) copy.usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  }
  const VkResult r = d.vk.CreateImage(device, &copy, alloc, out);
  if (r == VK_SUCCESS && L().capturing()) {
    Lock lock(L().mutex());
    d.image_usage[*out] = copy.usage;
    d.image_formats[*out] = info->format;
    if (depth) d.depth_images[*out] = DepthImage{info->format, info->extent.width, info->extent.height};
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyImage(VkDevice device, VkImage image, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(image, d.depth_images, d.image_usage, d.image_formats, d.image_keys);
  d.vk.DestroyImage(device, image, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateImageView(VkDevice device, const VkImageViewCreateInfo* info,
                                               const VkAllocationCallbacks* alloc, VkImageView* out) {
  Device& d = dev(device);
  const VkResult r = d.vk.CreateImageView(device, info, alloc, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    d.views[*out] = ImageViewInfo{info->image, info->format};
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyImageView(VkDevice device, VkImageView view, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(view, d.views);
  d.vk.DestroyImageView(device, view, alloc);
}

// ---------------------------------------------------------------------------------------------
// Swapchains: their images are read back at each present.

VKAPI_ATTR VkResult VKAPI_CALL CreateSwapchainKHR(VkDevice device, const VkSwapchainCreateInfoKHR* info,
                                                  const VkAllocationCallbacks* alloc, VkSwapchainKHR* out) {
  Device& d = dev(device);
  VkSwapchainCreateInfoKHR copy = *info;
  bool readable = false;
  if (L().capturing() && d.instance && d.instance->GetPhysicalDeviceSurfaceCapabilitiesKHR) {
    VkSurfaceCapabilitiesKHR caps{};
    if (d.instance->GetPhysicalDeviceSurfaceCapabilitiesKHR(d.physical, info->surface, &caps) == VK_SUCCESS &&
        (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT)) {
      copy.imageUsage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      readable = true;
    }
  }
  const VkResult r = d.vk.CreateSwapchainKHR(device, &copy, alloc, out);
  if (r != VK_SUCCESS) return r;
  uint32_t count = 0;
  d.vk.GetSwapchainImagesKHR(device, *out, &count, nullptr);
  SwapchainInfo s;
  s.images.resize(count);
  d.vk.GetSwapchainImagesKHR(device, *out, &count, s.images.data());
  s.format = info->imageFormat;
  s.extent = info->imageExtent;
  s.readable = readable;
  Lock lock(L().mutex());
  for (VkImage image : s.images) d.image_usage[image] = copy.imageUsage;
  if (!readable && L().capturing()) L().reportOnce("the swapchain's images cannot be read back: no colour captured");
  d.swapchains[*out] = std::move(s);
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroySwapchainKHR(VkDevice device, VkSwapchainKHR swapchain,
                                               const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(swapchain, d.swapchains);
  d.vk.DestroySwapchainKHR(device, swapchain, alloc);
}

// ---------------------------------------------------------------------------------------------
// Render passes and framebuffers: the id attachment.

// Render passes of Vulkan 1.0's structures and of the "2" ones (vkCreateRenderPass2), edited alike.
struct RenderPass1 {
  using Info = VkRenderPassCreateInfo;
  using Attachment = VkAttachmentDescription;
  using Subpass = VkSubpassDescription;
  using Reference = VkAttachmentReference;
  static Reference reference(uint32_t attachment, VkImageLayout layout) { return {attachment, layout}; }
  static Attachment attachment() { return Attachment{}; }
  static bool multiview(const Subpass&) { return false; }
};
struct RenderPass2 {
  using Info = VkRenderPassCreateInfo2;
  using Attachment = VkAttachmentDescription2;
  using Subpass = VkSubpassDescription2;
  using Reference = VkAttachmentReference2;
  static Reference reference(uint32_t attachment, VkImageLayout layout) {
    return {VK_STRUCTURE_TYPE_ATTACHMENT_REFERENCE_2, nullptr, attachment, layout, VK_IMAGE_ASPECT_COLOR_BIT};
  }
  static Attachment attachment() { return Attachment{VK_STRUCTURE_TYPE_ATTACHMENT_DESCRIPTION_2}; }
  static bool multiview(const Subpass& s) { return s.viewMask != 0; }
};

// The id attachment added to every single-sampled subpass with depth, the depth stored. `copy` is
// the create info to pass on (pointing into the vectors given).
template <typename P>
struct EditedRenderPass {
  RenderPassInfo rp;
  typename P::Info copy;
  std::vector<typename P::Attachment> attachments;
  std::vector<typename P::Subpass> subpasses;
  std::vector<std::vector<typename P::Reference>> colors, resolves;

  EditedRenderPass(const Device& d, const typename P::Info* info) : copy(*info) {
    rp.attachment_count = info->attachmentCount;
    for (uint32_t a = 0; a < info->attachmentCount; ++a) {
      rp.formats.push_back(info->pAttachments[a].format);
      rp.final_layouts.push_back(info->pAttachments[a].finalLayout);
    }
    rp.id_location.assign(info->subpassCount, -1);
    rp.depth_attachment.assign(info->subpassCount, -1);
    rp.color_attachment.assign(info->subpassCount, -1);
    attachments.assign(info->pAttachments, info->pAttachments + info->attachmentCount);
    subpasses.assign(info->pSubpasses, info->pSubpasses + info->subpassCount);
    colors.resize(info->subpassCount);
    resolves.resize(info->subpassCount);
    bool any = false;
    for (uint32_t s = 0; s < info->subpassCount && L().capturing() && d.primitive_id; ++s) {
      const typename P::Subpass& sp = info->pSubpasses[s];
      if (!sp.pDepthStencilAttachment || sp.pDepthStencilAttachment->attachment == VK_ATTACHMENT_UNUSED) continue;
      const uint32_t depth = sp.pDepthStencilAttachment->attachment;
      rp.depth_attachment[s] = static_cast<int>(depth);
      if (sp.colorAttachmentCount > 0 && sp.pColorAttachments[0].attachment != VK_ATTACHMENT_UNUSED)
        rp.color_attachment[s] = static_cast<int>(sp.pColorAttachments[0].attachment);
      if (attachments[depth].samples != VK_SAMPLE_COUNT_1_BIT || P::multiview(sp)) {
        rp.why_no_ids = P::multiview(sp) ? "multiview subpass" : "multisampled depth attachment";
        continue;
      }
      attachments[depth].storeOp = VK_ATTACHMENT_STORE_OP_STORE;  // read back at the pass's end
      colors[s].assign(sp.pColorAttachments, sp.pColorAttachments + sp.colorAttachmentCount);
      rp.id_location[s] = static_cast<int>(sp.colorAttachmentCount);
      colors[s].push_back(P::reference(info->attachmentCount, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL));
      subpasses[s].colorAttachmentCount = static_cast<uint32_t>(colors[s].size());
      subpasses[s].pColorAttachments = colors[s].data();
      if (sp.pResolveAttachments) {
        resolves[s].assign(sp.pResolveAttachments, sp.pResolveAttachments + sp.colorAttachmentCount);
        resolves[s].push_back(P::reference(VK_ATTACHMENT_UNUSED, VK_IMAGE_LAYOUT_UNDEFINED));
        subpasses[s].pResolveAttachments = resolves[s].data();
      }
      any = true;
    }
    if (any) {
      rp.id_attachment = info->attachmentCount;
      typename P::Attachment id = P::attachment();
      id.format = kIdFormat;
      id.samples = VK_SAMPLE_COUNT_1_BIT;
      id.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      id.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      id.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
      id.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
      id.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      id.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      attachments.push_back(id);
      copy.attachmentCount = static_cast<uint32_t>(attachments.size());
      copy.pAttachments = attachments.data();
      copy.pSubpasses = subpasses.data();
    } else if (rp.why_no_ids.empty()) {
      rp.why_no_ids = !L().capturing() || d.primitive_id ? "no depth attachment"
                                                         : "the device lacks geometryShader or independentBlend";
    }
  }
};

template <typename P, typename Create>
VkResult createRenderPassEdited(VkDevice device, const typename P::Info* info, const VkAllocationCallbacks* alloc,
                                VkRenderPass* out, Create create) {
  Device& d = dev(device);
  EditedRenderPass<P> edited(d, info);
  const VkResult r = create(device, &edited.copy, alloc, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    d.render_passes[*out] = std::move(edited.rp);
  }
  return r;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateRenderPass(VkDevice device, const VkRenderPassCreateInfo* info,
                                                const VkAllocationCallbacks* alloc, VkRenderPass* out) {
  return createRenderPassEdited<RenderPass1>(device, info, alloc, out, dev(device).vk.CreateRenderPass);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateRenderPass2(VkDevice device, const VkRenderPassCreateInfo2* info,
                                                 const VkAllocationCallbacks* alloc, VkRenderPass* out) {
  return createRenderPassEdited<RenderPass2>(device, info, alloc, out, dev(device).vk.CreateRenderPass2);
}

VKAPI_ATTR void VKAPI_CALL DestroyRenderPass(VkDevice device, VkRenderPass pass, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(pass, d.render_passes);
  d.vk.DestroyRenderPass(device, pass, alloc);
}

// The layer's id image (RGBA32UI: recording, draw, primitive, written) of one size.
IdImage makeIdImage(Device& d, uint32_t width, uint32_t height, uint32_t layers) {
  IdImage ids;
  VkImageCreateInfo image{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  image.imageType = VK_IMAGE_TYPE_2D;
  image.format = kIdFormat;
  image.extent = {width, height, 1};
  image.mipLevels = 1;
  image.arrayLayers = layers;
  image.samples = VK_SAMPLE_COUNT_1_BIT;
  image.tiling = VK_IMAGE_TILING_OPTIMAL;
  image.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  image.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  if (d.vk.CreateImage(d.device, &image, nullptr, &ids.image) != VK_SUCCESS) return IdImage{};
  VkMemoryRequirements req{};
  d.vk.GetImageMemoryRequirements(d.device, ids.image, &req);
  VkMemoryAllocateInfo mem{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mem.allocationSize = req.size;
  mem.memoryTypeIndex = Layer::memoryType(d, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (mem.memoryTypeIndex == UINT32_MAX) mem.memoryTypeIndex = Layer::memoryType(d, req.memoryTypeBits, 0);
  d.vk.AllocateMemory(d.device, &mem, nullptr, &ids.memory);
  d.vk.BindImageMemory(d.device, ids.image, ids.memory, 0);
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = ids.image;
  view.viewType = layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
  view.format = kIdFormat;
  view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
  d.vk.CreateImageView(d.device, &view, nullptr, &ids.view);
  return ids;
}

void destroyIdImage(Device& d, const IdImage& ids) {
  if (ids.view) d.vk.DestroyImageView(d.device, ids.view, nullptr);
  if (ids.image) d.vk.DestroyImage(d.device, ids.image, nullptr);
  if (ids.memory) d.vk.FreeMemory(d.device, ids.memory, nullptr);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateFramebuffer(VkDevice device, const VkFramebufferCreateInfo* info,
                                                 const VkAllocationCallbacks* alloc, VkFramebuffer* out) {
  Device& d = dev(device);
  FramebufferInfo fb;
  fb.render_pass = info->renderPass;
  fb.width = info->width, fb.height = info->height;
  bool ids = false;
  {
    Lock lock(L().mutex());
    auto rp = d.render_passes.find(info->renderPass);
    ids = rp != d.render_passes.end() && rp->second.id_attachment != VK_ATTACHMENT_UNUSED;
  }
  VkFramebufferCreateInfo copy = *info;
  if (info->flags & VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT) {
    // Imageless: the id attachment's description joins the program's; its view is given at each
    // vkCmdBeginRenderPass (BeginEdit).
    fb.imageless = true;
    auto* described = const_cast<VkFramebufferAttachmentsCreateInfo*>(findInChain<VkFramebufferAttachmentsCreateInfo>(
        info->pNext, VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO));
    if (!L().capturing() || !described) return d.vk.CreateFramebuffer(device, info, alloc, out);
    const VkFramebufferAttachmentsCreateInfo original = *described;
    std::vector<VkFramebufferAttachmentImageInfo> images(described->pAttachmentImageInfos,
                                                         described->pAttachmentImageInfos + described->attachmentImageInfoCount);
    static const VkFormat id_format = kIdFormat;
    if (ids) {
      VkFramebufferAttachmentImageInfo id{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENT_IMAGE_INFO};
      id.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      id.width = info->width, id.height = info->height, id.layerCount = std::max(1u, info->layers);
      id.viewFormatCount = 1;
      id.pViewFormats = &id_format;
      images.push_back(id);
      described->attachmentImageInfoCount = static_cast<uint32_t>(images.size());
      described->pAttachmentImageInfos = images.data();
      copy.attachmentCount = described->attachmentImageInfoCount;
      fb.ids = makeIdImage(d, info->width, info->height, std::max(1u, info->layers));
    }
    const VkResult r = d.vk.CreateFramebuffer(device, &copy, alloc, out);
    fb.create = *info;
    fb.create.pNext = nullptr;
    fb.create.attachmentCount = copy.attachmentCount;
    fb.image_infos = images;
    for (VkFramebufferAttachmentImageInfo& image : fb.image_infos) {
      fb.view_formats.emplace_back(image.pViewFormats, image.pViewFormats + image.viewFormatCount);
      image.pNext = nullptr;
    }
    *described = original;
    Lock lock(L().mutex());
    if (r == VK_SUCCESS) d.framebuffers[*out] = fb;
    else destroyIdImage(d, fb.ids);
    return r;
  }
  fb.views.assign(info->pAttachments, info->pAttachments + info->attachmentCount);
  std::vector<VkImageView> views = fb.views;
  if (ids) {
    fb.ids = makeIdImage(d, info->width, info->height, std::max(1u, info->layers));
    views.push_back(fb.ids.view);
    copy.attachmentCount = static_cast<uint32_t>(views.size());
    copy.pAttachments = views.data();
  }
  const VkResult r = d.vk.CreateFramebuffer(device, &copy, alloc, out);
  Lock lock(L().mutex());
  if (r == VK_SUCCESS) d.framebuffers[*out] = fb;
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyFramebuffer(VkDevice device, VkFramebuffer framebuffer,
                                              const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  FramebufferInfo fb;
  {
    Lock lock(L().mutex());
    auto f = d.framebuffers.find(framebuffer);
    if (f != d.framebuffers.end()) fb = f->second, d.framebuffers.erase(f);
  }
  d.vk.DestroyFramebuffer(device, framebuffer, alloc);
  for (auto& [usages, shadow] : fb.shadows) d.vk.DestroyFramebuffer(device, shadow, nullptr);
  destroyIdImage(d, fb.ids);
}

// ---------------------------------------------------------------------------------------------
// Shaders, layouts, descriptors, pipelines.

VKAPI_ATTR VkResult VKAPI_CALL CreateShaderModule(VkDevice device, const VkShaderModuleCreateInfo* info,
                                                  const VkAllocationCallbacks* alloc, VkShaderModule* out) {
  Device& d = dev(device);
  const VkResult r = d.vk.CreateShaderModule(device, info, alloc, out);
  if (r == VK_SUCCESS && L().capturing()) {
    Lock lock(L().mutex());
    d.modules[*out].assign(info->pCode, info->pCode + info->codeSize / 4);
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyShaderModule(VkDevice device, VkShaderModule module,
                                               const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(module, d.modules);
  d.vk.DestroyShaderModule(device, module, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL CreatePipelineLayout(VkDevice device, const VkPipelineLayoutCreateInfo* info,
                                                    const VkAllocationCallbacks* alloc, VkPipelineLayout* out) {
  Device& d = dev(device);
  LayoutInfo layout;
  layout.set_layouts.assign(info->pSetLayouts, info->pSetLayouts + info->setLayoutCount);
  std::vector<VkPushConstantRange> ranges(info->pPushConstantRanges,
                                          info->pPushConstantRanges + info->pushConstantRangeCount);
  VkPipelineLayoutCreateInfo copy = *info;
  if (L().capturing()) {
    // The layer's 8 bytes go past every range of the program's; a range that already has the
    // fragment stage is extended to them (one range per stage), else one of the fragment's added.
    uint32_t end = 0;
    for (const VkPushConstantRange& r : ranges) end = std::max(end, r.offset + r.size);
    layout.layer_offset = (end + 3u) & ~3u;
    if (layout.layer_offset + 8 <= d.limits.maxPushConstantsSize) {
      auto fragment = std::find_if(ranges.begin(), ranges.end(), [](const VkPushConstantRange& r) {
        return (r.stageFlags & VK_SHADER_STAGE_FRAGMENT_BIT) != 0;
      });
      if (fragment != ranges.end()) {
        fragment->size = layout.layer_offset + 8 - fragment->offset;
        layout.layer_stages = fragment->stageFlags;
      } else {
        ranges.push_back({VK_SHADER_STAGE_FRAGMENT_BIT, layout.layer_offset, 8});
        layout.layer_stages = VK_SHADER_STAGE_FRAGMENT_BIT;
      }
      copy.pushConstantRangeCount = static_cast<uint32_t>(ranges.size());
      copy.pPushConstantRanges = ranges.data();
    }
  }
  // Push constants full (SuperTuxKart uses all 128 bytes): the words come from the layer's uniform
  // buffer at the highest set index, the sets between the program's and it left empty.
  std::vector<VkDescriptorSetLayout> sets;
  if (L().capturing() && layout.layer_stages == 0) {
    Lock lock(L().mutex());
    if (L().ensureIdBuffer(d) && info->setLayoutCount < static_cast<uint32_t>(d.id_buffer.set_index)) {
      sets = layout.set_layouts;
      sets.resize(static_cast<size_t>(d.id_buffer.set_index), d.id_buffer.empty);
      sets.push_back(d.id_buffer.layout);
      copy.setLayoutCount = static_cast<uint32_t>(sets.size());
      copy.pSetLayouts = sets.data();
      layout.id_set = d.id_buffer.set_index;
    }
  }
  const VkResult r = d.vk.CreatePipelineLayout(device, &copy, alloc, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    d.layouts[*out] = layout;
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyPipelineLayout(VkDevice device, VkPipelineLayout layout,
                                                 const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(layout, d.layouts);
  d.vk.DestroyPipelineLayout(device, layout, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDescriptorSetLayout(VkDevice device, const VkDescriptorSetLayoutCreateInfo* info,
                                                         const VkAllocationCallbacks* alloc,
                                                         VkDescriptorSetLayout* out) {
  Device& d = dev(device);
  const VkResult r = d.vk.CreateDescriptorSetLayout(device, info, alloc, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    DescriptorSetLayoutInfo& l = d.set_layouts[*out];
    for (uint32_t b = 0; b < info->bindingCount; ++b)
      l.bindings[info->pBindings[b].binding] = {info->pBindings[b].descriptorType, info->pBindings[b].descriptorCount};
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyDescriptorSetLayout(VkDevice device, VkDescriptorSetLayout layout,
                                                      const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(layout, d.set_layouts);
  d.vk.DestroyDescriptorSetLayout(device, layout, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL AllocateDescriptorSets(VkDevice device, const VkDescriptorSetAllocateInfo* info,
                                                      VkDescriptorSet* out) {
  Device& d = dev(device);
  const VkResult r = d.vk.AllocateDescriptorSets(device, info, out);
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    for (uint32_t i = 0; i < info->descriptorSetCount; ++i) d.sets[out[i]] = DescriptorSetInfo{info->pSetLayouts[i], {}};
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL UpdateDescriptorSets(VkDevice device, uint32_t write_count, const VkWriteDescriptorSet* writes,
                                                uint32_t copy_count, const VkCopyDescriptorSet* copies) {
  Device& d = dev(device);
  {
    Lock lock(L().mutex());
    for (uint32_t i = 0; i < write_count; ++i) {
      const VkWriteDescriptorSet& w = writes[i];
      const VkDescriptorType t = w.descriptorType;
      if ((t == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER || t == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE) && w.pImageInfo &&
          w.dstArrayElement == 0) {
        d.sets[w.dstSet].images[w.dstBinding] = w.pImageInfo[0].imageView;
        continue;
      }
      const bool dynamic = t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC || t == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC;
      if (!(dynamic || t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || t == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)) continue;
      if (w.dstArrayElement != 0 || !w.pBufferInfo) continue;
      d.sets[w.dstSet].buffers[w.dstBinding] =
          DescriptorBuffer{w.pBufferInfo[0].buffer, w.pBufferInfo[0].offset, w.pBufferInfo[0].range, dynamic};
    }
    for (uint32_t i = 0; i < copy_count; ++i) {
      const VkCopyDescriptorSet& c = copies[i];
      auto from = d.sets[c.srcSet].buffers.find(c.srcBinding);
      if (c.srcArrayElement == 0 && c.dstArrayElement == 0 && from != d.sets[c.srcSet].buffers.end())
        d.sets[c.dstSet].buffers[c.dstBinding] = from->second;
      auto image = d.sets[c.srcSet].images.find(c.srcBinding);
      if (c.srcArrayElement == 0 && c.dstArrayElement == 0 && image != d.sets[c.srcSet].images.end())
        d.sets[c.dstSet].images[c.dstBinding] = image->second;
    }
  }
  d.vk.UpdateDescriptorSets(device, write_count, writes, copy_count, copies);
}

// What the layer knows of one graphics pipeline, and its fragment shader rewritten for ids when
// it draws into a subpass with the id attachment.
PipelineInfo describePipeline(Device& d, const VkGraphicsPipelineCreateInfo& info, VkPipelineShaderStageCreateInfo* stages,
                              VkPipelineColorBlendStateCreateInfo* blend,
                              std::vector<VkPipelineColorBlendAttachmentState>& blend_attachments, int* dynamic_location) {
  PipelineInfo p;
  p.layout = info.layout;
  const std::vector<uint32_t>* vertex = nullptr;
  const std::vector<uint32_t>* fragment = nullptr;
  int fragment_stage = -1;
  std::string fragment_entry;
  for (uint32_t s = 0; s < info.stageCount; ++s) {
    auto m = d.modules.find(info.pStages[s].module);
    if (m == d.modules.end()) continue;
    if (info.pStages[s].stage == VK_SHADER_STAGE_VERTEX_BIT) vertex = &m->second;
    if (info.pStages[s].stage == VK_SHADER_STAGE_FRAGMENT_BIT) {
      fragment = &m->second;
      fragment_stage = static_cast<int>(s);
      fragment_entry = info.pStages[s].pName;
    }
  }
  if (fragment) p.images = reflectModule(*fragment).images;
  uint64_t key = 0;
  if (vertex) key = combineKeys(key, contentKey(vertex->data(), vertex->size() * 4));
  if (fragment) key = combineKeys(key, contentKey(fragment->data(), fragment->size() * 4));
  p.program_key = key;
  if (info.pDepthStencilState) p.depth_test = info.pDepthStencilState->depthTestEnable;
  if (info.pInputAssemblyState) p.topology = info.pInputAssemblyState->topology;
  bool writes_color = false;
  if (info.pColorBlendState)
    for (uint32_t a = 0; a < info.pColorBlendState->attachmentCount; ++a)
      writes_color |= info.pColorBlendState->pAttachments[a].colorWriteMask != 0;
  p.depth_only = !fragment || !writes_color;

  // Matrices and position by the profile's names, read from the vertex shader's debug names.
  ModuleReflection reflection;
  if (vertex) reflection = reflectModule(*vertex);
  const ProgramProfile* profile = L().profile().match(reflection.names_text, key);
  p.overlay = profile->overlay;
  bool dynamic_viewport = false;
  if (info.pDynamicState)
    for (uint32_t k = 0; k < info.pDynamicState->dynamicStateCount; ++k)
      dynamic_viewport |= info.pDynamicState->pDynamicStates[k] == VK_DYNAMIC_STATE_VIEWPORT ||
                          info.pDynamicState->pDynamicStates[k] == VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT;
  if (!dynamic_viewport && info.pViewportState && info.pViewportState->viewportCount > 0 && info.pViewportState->pViewports)
    p.static_y_down = info.pViewportState->pViewports[0].height > 0 ? 1 : 0;
  p.reads_base_instance = reflection.reads_base_instance;
  p.deforming = profile->deforming == Deforming::kYes;
  const std::string* names[3] = {&profile->world, &profile->view, &profile->projection};
  MatrixSource* sources[3] = {&p.world, &p.view, &p.projection};
  for (int k = 0; k < 3; ++k) {
    if (names[k]->empty()) continue;
    p.expected_matrices |= static_cast<uint8_t>(1u << k);
    auto m = reflection.members.find(*names[k]);
    if (m != reflection.members.end() && m->second.columns == 4 && m->second.rows == 4)
      *sources[k] = MatrixSource{true, m->second};
  }
  const std::string* parts[3] = {&profile->instance_translation, &profile->instance_rotation, &profile->instance_scale};
  for (int k = 0; k < 3; ++k) {
    if (parts[k]->empty()) continue;
    p.expected_matrices |= kHasWorld;
    auto m = reflection.members.find(*parts[k]);
    if (m != reflection.members.end() && m->second.components >= 3) p.instance_parts[k] = MatrixSource{true, m->second};
  }
  p.instance_rotation_conjugate = profile->instance_rotation_conjugate;
  if (profile->hasInstanceTransform()) p.world = MatrixSource{};  // the instance's world replaces it
  uint32_t position_location = 0;
  if (!profile->position.empty()) {
    auto in = reflection.input_locations.find(profile->position);
    if (in != reflection.input_locations.end()) position_location = in->second;
  }
  if (const VkPipelineVertexInputStateCreateInfo* vi = info.pVertexInputState) {
    for (uint32_t b = 0; b < vi->vertexBindingDescriptionCount; ++b)
      p.strides[vi->pVertexBindingDescriptions[b].binding] = vi->pVertexBindingDescriptions[b].stride;
    for (uint32_t a = 0; a < vi->vertexAttributeDescriptionCount; ++a) {
      const VkVertexInputAttributeDescription& at = vi->pVertexAttributeDescriptions[a];
      if (at.location != position_location) continue;
      p.has_position = true;
      p.position_binding = at.binding;
      p.position_format = at.format;
      p.position_offset = at.offset;
    }
  }

  // Ids: only in subpasses the layer gave its attachment, or renderings with a single-sampled depth
  // image (dynamic rendering: the caller adds the id format to the pipeline's rendering info).
  uint32_t location = 0;
  if (info.renderPass == VK_NULL_HANDLE) {
    const auto* rendering =
        findInChain<VkPipelineRenderingCreateInfo>(info.pNext, VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO);
    const bool single_sampled =
        !info.pMultisampleState || info.pMultisampleState->rasterizationSamples == VK_SAMPLE_COUNT_1_BIT;
    if (!rendering || rendering->depthAttachmentFormat == VK_FORMAT_UNDEFINED || !d.primitive_id) {
      p.why_no_ids = "no depth attachment";
      return p;
    }
    if (!single_sampled || rendering->viewMask != 0) {
      p.why_no_ids = single_sampled ? "multiview rendering" : "multisampled rendering";
      return p;
    }
    location = rendering->colorAttachmentCount;
    *dynamic_location = static_cast<int>(location);
  } else {
    auto rp = d.render_passes.find(info.renderPass);
    if (rp == d.render_passes.end() || info.subpass >= rp->second.id_location.size() ||
        rp->second.id_location[info.subpass] < 0) {
      p.why_no_ids = rp == d.render_passes.end() ? "render pass unknown to the layer" : rp->second.why_no_ids;
      return p;
    }
    location = static_cast<uint32_t>(rp->second.id_location[info.subpass]);
  }
  // The blend state always gets the attachment (the subpass has it); written only with ids.
  if (blend && info.pColorBlendState) {
    *blend = *info.pColorBlendState;
    blend_attachments.assign(info.pColorBlendState->pAttachments,
                             info.pColorBlendState->pAttachments + info.pColorBlendState->attachmentCount);
    VkPipelineColorBlendAttachmentState id{};
    id.colorWriteMask = 0;
    blend_attachments.resize(location, VkPipelineColorBlendAttachmentState{});
    blend_attachments.push_back(id);
    blend->attachmentCount = static_cast<uint32_t>(blend_attachments.size());
    blend->pAttachments = blend_attachments.data();
  }
  auto layout = d.layouts.find(info.layout);
  if (p.depth_only) {
    p.why_no_ids = "depth only";
  } else if (p.overlay || !p.depth_test) {
    // Never recorded (the 2D overlay, draws without depth test): they write no ids at all, so
    // the pixels keep the ids of the scene they are drawn over, as with the OpenGL layer.
    p.why_no_ids = "not recorded";
  } else if (layout == d.layouts.end() || (layout->second.layer_stages == 0 && layout->second.id_set < 0)) {
    p.why_no_ids = "no room in the push constants or descriptor sets for the layer's id";
  } else if (!blend) {
    p.why_no_ids = "no colour blend state";
  } else {
    std::string why;
    const std::vector<uint32_t> rewritten =
        addIdOutput(*fragment, fragment_entry,
                    IdOutput{location, layout->second.layer_offset, layout->second.layer_stages ? -1 : layout->second.id_set},
                    why);
    if (rewritten.empty()) {
      p.why_no_ids = "fragment shader not rewritten: " + why;
    } else {
      VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      module.codeSize = rewritten.size() * 4;
      module.pCode = rewritten.data();
      VkShaderModule made = VK_NULL_HANDLE;
      if (d.vk.CreateShaderModule(d.device, &module, nullptr, &made) == VK_SUCCESS) {
        stages[fragment_stage].module = made;
        p.layer_modules.push_back(made);
        // An id names the surface the depth image holds: a blended draw that writes no depth is an
        // effect (rain, glare, smoke) and takes no pixel's id; a pass at equal depth (after a depth
        // pre-pass, whose depth-only draws are not recorded) names the surface it shades.
        const VkPipelineDepthStencilStateCreateInfo* ds = info.pDepthStencilState;
        const bool depth_writes = ds && ds->depthTestEnable && ds->depthWriteEnable;
        const bool shades_decided = ds && ds->depthTestEnable && !ds->depthWriteEnable && ds->depthCompareOp == VK_COMPARE_OP_EQUAL;
        const bool blended = info.pColorBlendState->attachmentCount > 0 && info.pColorBlendState->pAttachments[0].blendEnable;
        blend_attachments.back().colorWriteMask = !blended || depth_writes || shades_decided ? 0xf : 0;
        p.ids = true;
      } else {
        p.why_no_ids = "the rewritten fragment shader was refused by the driver";
      }
    }
  }
  return p;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateGraphicsPipelines(VkDevice device, VkPipelineCache cache, uint32_t count,
                                                       const VkGraphicsPipelineCreateInfo* infos,
                                                       const VkAllocationCallbacks* alloc, VkPipeline* out) {
  Device& d = dev(device);
  if (!L().capturing()) return d.vk.CreateGraphicsPipelines(device, cache, count, infos, alloc, out);
  std::vector<VkGraphicsPipelineCreateInfo> copies(infos, infos + count);
  std::vector<std::vector<VkPipelineShaderStageCreateInfo>> stages(count);
  std::vector<VkPipelineColorBlendStateCreateInfo> blends(count);
  std::vector<std::vector<VkPipelineColorBlendAttachmentState>> blend_attachments(count);
  std::vector<PipelineInfo> described(count);
  // Dynamic rendering: the id format is added to the program's VkPipelineRenderingCreateInfo for
  // the call, and its own list put back after.
  std::vector<std::vector<VkFormat>> formats(count);
  std::vector<std::pair<VkPipelineRenderingCreateInfo*, VkPipelineRenderingCreateInfo>> restore;
  {
    Lock lock(L().mutex());
    for (uint32_t i = 0; i < count; ++i) {
      stages[i].assign(infos[i].pStages, infos[i].pStages + infos[i].stageCount);
      int dynamic_location = -1;
      described[i] = describePipeline(d, infos[i], stages[i].data(), infos[i].pColorBlendState ? &blends[i] : nullptr,
                                      blend_attachments[i], &dynamic_location);
      copies[i].pStages = stages[i].data();
      if (infos[i].pColorBlendState && !blend_attachments[i].empty()) copies[i].pColorBlendState = &blends[i];
      if (dynamic_location >= 0) {
        auto* rendering = const_cast<VkPipelineRenderingCreateInfo*>(
            findInChain<VkPipelineRenderingCreateInfo>(infos[i].pNext, VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO));
        restore.emplace_back(rendering, *rendering);
        formats[i].assign(rendering->pColorAttachmentFormats,
                          rendering->pColorAttachmentFormats + rendering->colorAttachmentCount);
        formats[i].push_back(kIdFormat);
        rendering->colorAttachmentCount = static_cast<uint32_t>(formats[i].size());
        rendering->pColorAttachmentFormats = formats[i].data();
      }
    }
  }
  const VkResult r = d.vk.CreateGraphicsPipelines(device, cache, count, copies.data(), alloc, out);
  for (auto& [rendering, original] : restore) *rendering = original;
  Lock lock(L().mutex());
  for (uint32_t i = 0; i < count; ++i) {
    if (out[i] != VK_NULL_HANDLE) {
      d.pipelines[out[i]] = described[i];
    } else {
      for (VkShaderModule m : described[i].layer_modules) d.vk.DestroyShaderModule(device, m, nullptr);
    }
    if (!described[i].why_no_ids.empty() && described[i].why_no_ids != "depth only" &&
        described[i].why_no_ids != "not recorded")
      L().reportOnce("pipelines without ids: " + described[i].why_no_ids);
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyPipeline(VkDevice device, VkPipeline pipeline, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  std::vector<VkShaderModule> modules;
  {
    Lock lock(L().mutex());
    auto p = d.pipelines.find(pipeline);
    if (p != d.pipelines.end()) modules = p->second.layer_modules, d.pipelines.erase(p);
  }
  d.vk.DestroyPipeline(device, pipeline, alloc);
  for (VkShaderModule m : modules) d.vk.DestroyShaderModule(device, m, nullptr);
}

// ---------------------------------------------------------------------------------------------
// Command buffers.

Recording* recording(Device& d, VkCommandBuffer cb) {
  auto r = d.recordings.find(cb);
  return r == d.recordings.end() ? nullptr : r->second.get();
}

VKAPI_ATTR VkResult VKAPI_CALL BeginCommandBuffer(VkCommandBuffer cb, const VkCommandBufferBeginInfo* info) {
  Device& d = dev(cb);
  if (L().capturing()) {
    Lock lock(L().mutex());
    std::shared_ptr<Recording>& r = d.recordings[cb];
    if (r && r.use_count() > 1) d.retired.push_back(r);  // a frame still holds it
    else if (r) L().freeRecording(d, *r);
    r = std::make_shared<Recording>();
    r->serial = L().nextSerial();
    if (info->pInheritanceInfo && (info->flags & VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT)) {
      r->render_pass = info->pInheritanceInfo->renderPass;
      r->subpass = info->pInheritanceInfo->subpass;
      r->framebuffer = info->pInheritanceInfo->framebuffer;
    }
  }
  return d.vk.BeginCommandBuffer(cb, info);
}

VKAPI_ATTR void VKAPI_CALL FreeCommandBuffers(VkDevice device, VkCommandPool pool, uint32_t count,
                                              const VkCommandBuffer* cbs) {
  Device& d = dev(device);
  {
    Lock lock(L().mutex());
    for (uint32_t i = 0; i < count; ++i) {
      auto r = d.recordings.find(cbs[i]);
      if (r == d.recordings.end()) continue;
      if (r->second.use_count() > 1) d.retired.push_back(r->second);
      else L().freeRecording(d, *r->second);
      d.recordings.erase(r);
    }
  }
  d.vk.FreeCommandBuffers(device, pool, count, cbs);
}

// An imageless framebuffer whose descriptions name the usage of the images begun with: the program's
// own, or the layer's copy of it where the layer added usage to those images (depth images and the
// swapchain's are read back).
VkFramebuffer framebufferForUsage(Device& d, FramebufferInfo& fb, VkFramebuffer own, const std::vector<VkImageView>& views) {
  std::vector<VkImageUsageFlags> usages;
  bool same = true;
  for (size_t i = 0; i < fb.image_infos.size() && i < views.size(); ++i) {
    VkImageUsageFlags usage = fb.image_infos[i].usage;
    auto view = d.views.find(views[i]);
    if (view != d.views.end()) {
      auto image = d.image_usage.find(view->second.image);
      if (image != d.image_usage.end()) usage = image->second;
    }
    same &= usage == fb.image_infos[i].usage;
    usages.push_back(usage);
  }
  if (same) return own;
  VkFramebuffer& shadow = fb.shadows[usages];
  if (shadow) return shadow;
  std::vector<VkFramebufferAttachmentImageInfo> images = fb.image_infos;
  for (size_t i = 0; i < images.size(); ++i) {
    if (i < usages.size()) images[i].usage = usages[i];
    images[i].pViewFormats = fb.view_formats[i].data();
  }
  VkFramebufferAttachmentsCreateInfo described{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO};
  described.attachmentImageInfoCount = static_cast<uint32_t>(images.size());
  described.pAttachmentImageInfos = images.data();
  VkFramebufferCreateInfo create = fb.create;
  create.pNext = &described;
  if (d.vk.CreateFramebuffer(d.device, &create, nullptr, &shadow) != VK_SUCCESS) {
    fb.shadows.erase(usages);
    return own;
  }
  return shadow;
}

// What vkCmdBeginRenderPass(2) passes on: the clear values with the id attachment's (0), and for an
// imageless framebuffer the attachments with the layer's id view (VkRenderPassAttachmentBeginInfo,
// changed in place for the call; restore() puts the program's back).
struct BeginEdit {
  VkRenderPassBeginInfo copy{};
  std::vector<VkClearValue> clears;
  std::vector<VkImageView> views;
  VkRenderPassAttachmentBeginInfo* attachments = nullptr;
  VkRenderPassAttachmentBeginInfo original{};

  BeginEdit(Device& d, VkCommandBuffer cb, const VkRenderPassBeginInfo* info) : copy(*info) {
    Lock lock(L().mutex());
    Recording* r = recording(d, cb);
    if (r) {
      r->render_pass = info->renderPass;
      r->framebuffer = info->framebuffer;
      r->subpass = 0;
      r->pass = -1;
      r->pass_views.clear();
    }
    auto rp = d.render_passes.find(info->renderPass);
    const bool ids = rp != d.render_passes.end() && rp->second.id_attachment != VK_ATTACHMENT_UNUSED;
    if (ids) {
      clears.assign(info->pClearValues, info->pClearValues + info->clearValueCount);
      clears.resize(rp->second.id_attachment + 1, VkClearValue{});
      clears.back() = VkClearValue{};
      copy.clearValueCount = static_cast<uint32_t>(clears.size());
      copy.pClearValues = clears.data();
    }
    // An imageless framebuffer (with ids or not): its views' usage is what the layer made it.
    auto fb = d.framebuffers.find(info->framebuffer);
    attachments = const_cast<VkRenderPassAttachmentBeginInfo*>(findInChain<VkRenderPassAttachmentBeginInfo>(
        info->pNext, VK_STRUCTURE_TYPE_RENDER_PASS_ATTACHMENT_BEGIN_INFO));
    if (fb != d.framebuffers.end() && fb->second.imageless && attachments && !fb->second.image_infos.empty()) {
      original = *attachments;
      views.assign(attachments->pAttachments, attachments->pAttachments + attachments->attachmentCount);
      if (r) r->pass_views = views;
      if (ids && fb->second.ids.view) views.push_back(fb->second.ids.view);
      attachments->attachmentCount = static_cast<uint32_t>(views.size());
      attachments->pAttachments = views.data();
      copy.framebuffer = framebufferForUsage(d, fb->second, info->framebuffer, views);
    } else {
      attachments = nullptr;
    }
  }
  void restore() {
    if (attachments) *attachments = original;
  }
};

VKAPI_ATTR void VKAPI_CALL CmdBeginRenderPass(VkCommandBuffer cb, const VkRenderPassBeginInfo* info,
                                              VkSubpassContents contents) {
  Device& d = dev(cb);
  BeginEdit edit(d, cb, info);
  d.vk.CmdBeginRenderPass(cb, &edit.copy, contents);
  edit.restore();
}

VKAPI_ATTR void VKAPI_CALL CmdBeginRenderPass2(VkCommandBuffer cb, const VkRenderPassBeginInfo* info,
                                               const VkSubpassBeginInfo* subpass) {
  Device& d = dev(cb);
  BeginEdit edit(d, cb, info);
  d.vk.CmdBeginRenderPass2(cb, &edit.copy, subpass);
  edit.restore();
}

VKAPI_ATTR void VKAPI_CALL CmdNextSubpass(VkCommandBuffer cb, VkSubpassContents contents) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) ++r->subpass;
  }
  d.vk.CmdNextSubpass(cb, contents);
}

VKAPI_ATTR void VKAPI_CALL CmdNextSubpass2(VkCommandBuffer cb, const VkSubpassBeginInfo* begin, const VkSubpassEndInfo* end) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) ++r->subpass;
  }
  d.vk.CmdNextSubpass2(cb, begin, end);
}

// At the end of a render pass instance that drew recorded draws with ids: its depth and ids are
// copied into buffers of the layer's, read at the frame's present (and its colour, on a device
// without a swapchain: read when the frame's submission is done).
struct PassImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;  ///< where the pass left it, and leaves it again
  VkFormat format = VK_FORMAT_UNDEFINED;
};
void copyImages(Device& d, VkCommandBuffer cb, PassCapture& pc, VkImage id_image, PassImage depth, PassImage color);

// The pass's colour image to copy: its first colour attachment's, when the device has no swapchain
// and the image can be copied from.
PassImage colorToCopy(Device& d, VkImageView view, VkImageLayout layout) {
  if (!d.swapchains.empty() || !view) return {};
  auto v = d.views.find(view);
  if (v == d.views.end() || !isReadableColorFormat(v->second.format)) return {};
  auto usage = d.image_usage.find(v->second.image);
  if (usage == d.image_usage.end() || !(usage->second & VK_IMAGE_USAGE_TRANSFER_SRC_BIT)) {
    L().reportOnce("a scene colour attachment that cannot be copied from (made before the layer was loaded, or "
                   "with a format other than 8-bit RGBA/BGRA): frames without colour");
    return {};
  }
  return {v->second.image, layout, v->second.format};
}

void copyPassImages(Device& d, VkCommandBuffer cb, Recording& r) {
  if (r.pass < 0) return;
  PassCapture& pc = r.passes[static_cast<size_t>(r.pass)];
  auto fb = d.framebuffers.find(r.framebuffer);
  auto rp = d.render_passes.find(r.render_pass);
  if (fb == d.framebuffers.end() || rp == d.render_passes.end() || !fb->second.ids.image || pc.id_draws == 0) return;
  pc.width = fb->second.width, pc.height = fb->second.height;
  // The depth and colour attachments of the subpass that had the ids (the first such).
  int depth_attachment = -1, color_attachment = -1;
  for (size_t s = 0; s < rp->second.id_location.size(); ++s)
    if (rp->second.id_location[s] >= 0) {
      depth_attachment = rp->second.depth_attachment[s];
      color_attachment = rp->second.color_attachment[s];
      break;
    }
  PassImage depth, color;
  const std::vector<VkImageView>& views = fb->second.imageless ? r.pass_views : fb->second.views;
  if (depth_attachment >= 0 && static_cast<size_t>(depth_attachment) < views.size()) {
    auto view = d.views.find(views[static_cast<size_t>(depth_attachment)]);
    if (view != d.views.end() && d.depth_images.count(view->second.image)) {
      depth = {view->second.image, rp->second.final_layouts[static_cast<size_t>(depth_attachment)], view->second.format};
      pc.depth_format = view->second.format;
    }
  }
  if (color_attachment >= 0 && static_cast<size_t>(color_attachment) < views.size())
    color = colorToCopy(d, views[static_cast<size_t>(color_attachment)],
                        rp->second.final_layouts[static_cast<size_t>(color_attachment)]);
  copyImages(d, cb, pc, fb->second.ids.image, depth, color);
}

// Records the copies of a pass's ids (in COLOR_ATTACHMENT_OPTIMAL), depth and colour (each in the
// layout the pass left it in, where it is left again) into the layer's buffers, read with the frame.
void copyImages(Device& d, VkCommandBuffer cb, PassCapture& pc, VkImage id_image, PassImage depth, PassImage color) {
  const VkDeviceSize pixels = static_cast<VkDeviceSize>(pc.width) * pc.height;
  if (!L().createReadbackBuffer(d, pixels * 16, pc.id_buffer, pc.id_memory)) return;
  if (depth.image && !L().createReadbackBuffer(d, pixels * 4, pc.depth_buffer, pc.depth_memory)) depth = {};
  if (color.image && !L().createReadbackBuffer(d, pixels * 4, pc.color_buffer, pc.color_memory)) color = {};
  if (color.image) pc.color_format = color.format;

  const VkImageAspectFlags depth_aspect =
      pc.depth_format == VK_FORMAT_D16_UNORM || pc.depth_format == VK_FORMAT_D32_SFLOAT ||
              pc.depth_format == VK_FORMAT_X8_D24_UNORM_PACK32
          ? VK_IMAGE_ASPECT_DEPTH_BIT
          : VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
  std::vector<VkImageMemoryBarrier> to, back;
  to.push_back(imageBarrier(id_image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT));
  for (const auto& [image, aspect, written] :
       {std::tuple{depth, depth_aspect, VkAccessFlags(VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT)},
        std::tuple{color, VkImageAspectFlags(VK_IMAGE_ASPECT_COLOR_BIT), VkAccessFlags(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT)}}) {
    if (!image.image) continue;
    to.push_back(imageBarrier(image.image, image.layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, written,
                              VK_ACCESS_TRANSFER_READ_BIT, aspect));
    // Back to the layout the program's pass left it in.
    back.push_back(imageBarrier(image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image.layout, VK_ACCESS_TRANSFER_READ_BIT,
                                VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT, aspect));
  }
  d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, static_cast<uint32_t>(to.size()),
                          to.data());
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {pc.width, pc.height, 1};
  d.vk.CmdCopyImageToBuffer(cb, id_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.id_buffer, 1, &region);
  if (color.image)
    d.vk.CmdCopyImageToBuffer(cb, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.color_buffer, 1, &region);
  if (depth.image) {
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
    d.vk.CmdCopyImageToBuffer(cb, depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.depth_buffer, 1, &region);
  }
  if (!back.empty())
    d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                            nullptr, static_cast<uint32_t>(back.size()), back.data());
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                          nullptr);
}

void endRenderPass(Device& d, VkCommandBuffer cb) {
  Lock lock(L().mutex());
  if (Recording* r = recording(d, cb)) {
    copyPassImages(d, cb, *r);
    r->render_pass = VK_NULL_HANDLE;
    r->pass = -1;
  }
}

VKAPI_ATTR void VKAPI_CALL CmdEndRenderPass(VkCommandBuffer cb) {
  Device& d = dev(cb);
  d.vk.CmdEndRenderPass(cb);
  endRenderPass(d, cb);
}

VKAPI_ATTR void VKAPI_CALL CmdEndRenderPass2(VkCommandBuffer cb, const VkSubpassEndInfo* end) {
  Device& d = dev(cb);
  d.vk.CmdEndRenderPass2(cb, end);
  endRenderPass(d, cb);
}

// Dynamic rendering: a rendering with a single-sampled depth image of the program's gets the
// layer's id image as one more colour attachment, as pipelines made for it get the format.
VKAPI_ATTR void VKAPI_CALL CmdBeginRendering(VkCommandBuffer cb, const VkRenderingInfo* info) {
  Device& d = dev(cb);
  VkRenderingInfo copy = *info;
  std::vector<VkRenderingAttachmentInfo> colors;
  VkRenderingAttachmentInfo depth{};
  {
    Lock lock(L().mutex());
    Recording* r = recording(d, cb);
    if (r) r->rendering = false, r->pass = -1;
    const VkRenderingAttachmentInfo* program_depth = info->pDepthAttachment;
    auto view = program_depth && program_depth->imageView ? d.views.find(program_depth->imageView) : d.views.end();
    auto image = view != d.views.end() ? d.depth_images.find(view->second.image) : d.depth_images.end();
    if (r && L().capturing() && d.primitive_id && image != d.depth_images.end() && info->viewMask == 0) {
      const DepthImage& di = image->second;
      IdImage& ids = d.rendering_ids[{di.width, di.height}];
      if (!ids.image) ids = makeIdImage(d, di.width, di.height, 1);
      colors.assign(info->pColorAttachments, info->pColorAttachments + info->colorAttachmentCount);
      VkRenderingAttachmentInfo id{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      id.imageView = ids.view;
      id.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      id.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      id.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      colors.push_back(id);
      copy.colorAttachmentCount = static_cast<uint32_t>(colors.size());
      copy.pColorAttachments = colors.data();
      depth = *program_depth;
      depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;  // read back at the rendering's end
      copy.pDepthAttachment = &depth;
      r->rendering = true;
      r->rendering_ids = ids.image;
      r->rendering_depth = view->second.image;
      r->rendering_depth_layout = program_depth->imageLayout;
      r->rendering_depth_format = di.format;
      r->rendering_width = di.width;
      r->rendering_height = di.height;
      const PassImage color = info->colorAttachmentCount > 0
                                  ? colorToCopy(d, info->pColorAttachments[0].imageView, info->pColorAttachments[0].imageLayout)
                                  : PassImage{};
      r->rendering_color = color.image;
      r->rendering_color_layout = color.layout;
      r->rendering_color_format = color.format;
      // The id image enters the layout the attachment names (its contents are cleared anyway).
      const VkImageMemoryBarrier barrier = imageBarrier(ids.image, VK_IMAGE_LAYOUT_UNDEFINED,
                                                        VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, 0,
                                                        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
      d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                              VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr, 0, nullptr, 1, &barrier);
    }
  }
  d.vk.CmdBeginRendering(cb, &copy);
}

VKAPI_ATTR void VKAPI_CALL CmdEndRendering(VkCommandBuffer cb) {
  Device& d = dev(cb);
  d.vk.CmdEndRendering(cb);
  Lock lock(L().mutex());
  Recording* r = recording(d, cb);
  if (!r || !r->rendering) return;
  if (r->pass >= 0 && r->passes[static_cast<size_t>(r->pass)].id_draws > 0) {
    PassCapture& pc = r->passes[static_cast<size_t>(r->pass)];
    pc.width = r->rendering_width, pc.height = r->rendering_height;
    pc.depth_format = r->rendering_depth_format;
    copyImages(d, cb, pc, r->rendering_ids, {r->rendering_depth, r->rendering_depth_layout, r->rendering_depth_format},
               {r->rendering_color, r->rendering_color_layout, r->rendering_color_format});
  }
  r->rendering = false;
  r->pass = -1;
}

VKAPI_ATTR void VKAPI_CALL CmdBindPipeline(VkCommandBuffer cb, VkPipelineBindPoint point, VkPipeline pipeline) {
  Device& d = dev(cb);
  if (point == VK_PIPELINE_BIND_POINT_GRAPHICS) {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) {
      r->pipeline = pipeline;
      auto p = d.pipelines.find(pipeline);
      if (p != d.pipelines.end() && p->second.static_y_down >= 0) r->y_down = p->second.static_y_down == 1;
    }
  }
  d.vk.CmdBindPipeline(cb, point, pipeline);
}

VKAPI_ATTR void VKAPI_CALL CmdBindVertexBuffers(VkCommandBuffer cb, uint32_t first, uint32_t count,
                                                const VkBuffer* buffers, const VkDeviceSize* offsets) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb))
      for (uint32_t i = 0; i < count; ++i) r->vertex_buffers[first + i] = {buffers[i], offsets[i]};
  }
  d.vk.CmdBindVertexBuffers(cb, first, count, buffers, offsets);
}

VKAPI_ATTR void VKAPI_CALL CmdBindIndexBuffer(VkCommandBuffer cb, VkBuffer buffer, VkDeviceSize offset, VkIndexType type) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) r->index_buffer = buffer, r->index_offset = offset, r->index_type = type;
  }
  d.vk.CmdBindIndexBuffer(cb, buffer, offset, type);
}

VKAPI_ATTR void VKAPI_CALL CmdBindDescriptorSets(VkCommandBuffer cb, VkPipelineBindPoint point, VkPipelineLayout layout,
                                                 uint32_t first, uint32_t count, const VkDescriptorSet* sets,
                                                 uint32_t dynamic_count, const uint32_t* dynamic_offsets) {
  Device& d = dev(cb);
  if (point == VK_PIPELINE_BIND_POINT_GRAPHICS) {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) {
      uint32_t used = 0;
      for (uint32_t i = 0; i < count; ++i) {
        std::vector<uint32_t> offsets;
        auto s = d.sets.find(sets[i]);
        if (s != d.sets.end()) {
          auto l = d.set_layouts.find(s->second.layout);
          const uint32_t n = l == d.set_layouts.end() ? 0 : l->second.dynamicCount();
          for (uint32_t k = 0; k < n && used < dynamic_count; ++k) offsets.push_back(dynamic_offsets[used++]);
        }
        r->sets[first + i] = {sets[i], offsets};
      }
    }
  }
  d.vk.CmdBindDescriptorSets(cb, point, layout, first, count, sets, dynamic_count, dynamic_offsets);
}

VKAPI_ATTR void VKAPI_CALL CmdPushConstants(VkCommandBuffer cb, VkPipelineLayout layout, VkShaderStageFlags stages,
                                            uint32_t offset, uint32_t size, const void* values) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb))
      if (offset < r->push.size()) std::memcpy(r->push.data() + offset, values, std::min<size_t>(size, r->push.size() - offset));
  }
  d.vk.CmdPushConstants(cb, layout, stages, offset, size, values);
}

VKAPI_ATTR void VKAPI_CALL CmdSetViewport(VkCommandBuffer cb, uint32_t first, uint32_t count, const VkViewport* v) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb))
      if (first == 0 && count > 0) r->y_down = v[0].height > 0;
  }
  d.vk.CmdSetViewport(cb, first, count, v);
}

// Records one draw into the scene: its state now, and the layer's id words pushed before it.
bool recordDraw(Device& d, VkCommandBuffer cb, RecordedDraw draw) {
  Recording* r = recording(d, cb);
  if (!r) return false;
  auto p = d.pipelines.find(r->pipeline);
  const char* skipped = p == d.pipelines.end()  ? "pipeline unknown"
                        : p->second.depth_only  ? "depth only"
                        : !p->second.depth_test ? "no depth test"
                        : p->second.overlay     ? "overlay"
                                                : nullptr;
  L().countDraw(skipped ? skipped : "recorded");
  if (skipped) return false;
  const PipelineInfo& pi = p->second;
  // A render pass instance with draws: its depth and ids are read back at its end.
  if (r->pass < 0 && (r->render_pass || r->rendering)) {
    r->passes.emplace_back();
    r->pass = static_cast<int>(r->passes.size()) - 1;
  }
  draw.local = static_cast<uint32_t>(r->draws.size());
  draw.pipeline = r->pipeline;
  draw.pass = r->pass;
  draw.ids = pi.ids && r->pass >= 0;
  draw.y_down = r->y_down;
  if (pi.has_position) {
    auto vb = r->vertex_buffers.find(pi.position_binding);
    if (vb != r->vertex_buffers.end()) draw.vertex_buffer = vb->second.first, draw.vertex_buffer_offset = vb->second.second;
  }
  if (draw.indexed) {
    draw.index_buffer = r->index_buffer;
    draw.index_buffer_offset = r->index_offset;
    draw.index_type = r->index_type;
  }
  const MatrixSource* sources[6] = {&pi.world,  &pi.view, &pi.projection, &pi.instance_parts[0], &pi.instance_parts[1],
                                    &pi.instance_parts[2]};
  draw.rotation_conjugate = pi.instance_rotation_conjugate;
  for (const auto& [set_index, binding] : pi.images) {
    VkImage image = VK_NULL_HANDLE;
    auto set = r->sets.find(set_index);
    auto info = set == r->sets.end() ? d.sets.end() : d.sets.find(set->second.first);
    if (info != d.sets.end()) {
      auto view = info->second.images.find(binding);
      auto v = view == info->second.images.end() ? d.views.end() : d.views.find(view->second);
      if (v != d.views.end()) image = v->second.image;
    }
    draw.textures.push_back(image);
  }
  for (int k = 0; k < 6; ++k) {
    if (!sources[k]->known) continue;
    const BlockMember& m = sources[k]->member;
    if (m.push_constant) {
      if (k < 3 && m.offset + 64 <= r->push.size()) {
        draw.matrices[static_cast<size_t>(k)] = readMatrix(r->push.data() + m.offset, m);
        draw.matrix_flags |= static_cast<uint8_t>(1u << k);
      }
      continue;
    }
    auto set = r->sets.find(m.set);
    if (set == r->sets.end()) continue;
    auto info = d.sets.find(set->second.first);
    if (info == d.sets.end()) continue;
    auto buffer = info->second.buffers.find(m.binding);
    if (buffer == info->second.buffers.end()) continue;
    DescriptorBuffer b = buffer->second;
    if (b.dynamic) {
      // The dynamic offset of this binding: dynamic bindings take offsets in binding order.
      auto l = d.set_layouts.find(info->second.layout);
      uint32_t index = 0;
      if (l != d.set_layouts.end())
        for (const auto& [binding, desc] : l->second.bindings) {
          if (binding == m.binding) break;
          if (desc.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC || desc.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC)
            index += desc.count;
        }
      if (index < set->second.second.size()) b.offset += set->second.second[index];
    }
    // Per-instance data: the element of the draw's (first) instance.
    const uint32_t element = k >= 3 ? draw.first_instance * m.array_stride : 0;
    draw.pending.push_back(RecordedDraw::PendingRead{k, b, m.offset + element, m});
  }
  auto layout = d.layouts.find(pi.layout);
  if (draw.ids && layout != d.layouts.end()) {
    if (layout->second.layer_stages) {
      const uint32_t words[2] = {r->serial, draw.local + 1};
      d.vk.CmdPushConstants(cb, pi.layout, layout->second.layer_stages, layout->second.layer_offset, 8, words);
    } else {
      const uint32_t slot = L().takeIdSlot(d, r->serial, draw.local + 1);
      if (slot == UINT32_MAX) {
        draw.ids = false;
        L().reportOnce("more draws in flight than the layer's id buffer has slots: some draws without ids");
      } else {
        r->id_slots.push_back(slot);
        const uint32_t offset = slot * d.id_buffer.stride;
        d.vk.CmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pi.layout, static_cast<uint32_t>(layout->second.id_set),
                                   1, &d.id_buffer.set, 1, &offset);
      }
    }
    if (draw.ids) r->passes[static_cast<size_t>(r->pass)].id_draws++;
  }
  r->draws.push_back(draw);
  return true;
}

// A recorded draw of several instances is issued one instance at a time, each with its own id and
// world (the same pixels: a draw's instances are drawn in instance order) unless its vertex shader
// reads gl_BaseInstance, which splitting would change: then it is one draw (the first instance's).
bool splits(Device& d, VkCommandBuffer cb) {
  Recording* r = recording(d, cb);
  auto p = r ? d.pipelines.find(r->pipeline) : d.pipelines.end();
  return p != d.pipelines.end() && !p->second.reads_base_instance;
}

VKAPI_ATTR void VKAPI_CALL CmdDraw(VkCommandBuffer cb, uint32_t vertices, uint32_t instances, uint32_t first_vertex,
                                   uint32_t first_instance) {
  Device& d = dev(cb);
  if (L().capturing() && instances > 0) {
    Lock lock(L().mutex());
    RecordedDraw draw;
    draw.count = vertices, draw.first = first_vertex, draw.first_instance = first_instance;
    if (recordDraw(d, cb, draw) && splits(d, cb)) {
      for (uint32_t i = 0; i < instances; ++i) {
        if (i > 0) draw.first_instance = first_instance + i, recordDraw(d, cb, draw);
        d.vk.CmdDraw(cb, vertices, 1, first_vertex, first_instance + i);
      }
      return;
    }
  }
  d.vk.CmdDraw(cb, vertices, instances, first_vertex, first_instance);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndexed(VkCommandBuffer cb, uint32_t indices, uint32_t instances, uint32_t first_index,
                                          int32_t vertex_offset, uint32_t first_instance) {
  Device& d = dev(cb);
  if (L().capturing() && instances > 0) {
    Lock lock(L().mutex());
    RecordedDraw draw;
    draw.indexed = true;
    draw.count = indices, draw.first = first_index, draw.vertex_offset = vertex_offset, draw.first_instance = first_instance;
    if (recordDraw(d, cb, draw) && splits(d, cb)) {
      for (uint32_t i = 0; i < instances; ++i) {
        if (i > 0) draw.first_instance = first_instance + i, recordDraw(d, cb, draw);
        d.vk.CmdDrawIndexed(cb, indices, 1, first_index, vertex_offset, first_instance + i);
      }
      return;
    }
  }
  d.vk.CmdDrawIndexed(cb, indices, instances, first_index, vertex_offset, first_instance);
}

// Indirect draws: not recorded yet. One whose pipeline would be recorded is counted among the draws
// into the scene not recorded, and writes id 0 (no draw), not the id words a draw before it left.
void unrecordedDraw(Device& d, VkCommandBuffer cb, uint32_t count) {
  Recording* r = recording(d, cb);
  if (!r) return;
  auto p = d.pipelines.find(r->pipeline);
  if (p == d.pipelines.end() || p->second.depth_only || !p->second.depth_test || p->second.overlay) return;
  r->unrecorded += count;
  L().countDraw("indirect");
  auto layout = d.layouts.find(p->second.layout);
  if (!p->second.ids || layout == d.layouts.end()) return;
  if (layout->second.layer_stages) {
    const uint32_t words[2] = {0, 0};
    d.vk.CmdPushConstants(cb, p->second.layout, layout->second.layer_stages, layout->second.layer_offset, 8, words);
  } else {
    const uint32_t offset = 0;  // slot 0 of the id buffer holds (0, 0)
    d.vk.CmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p->second.layout,
                               static_cast<uint32_t>(layout->second.id_set), 1, &d.id_buffer.set, 1, &offset);
  }
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndirect(VkCommandBuffer cb, VkBuffer buffer, VkDeviceSize offset, uint32_t count,
                                           uint32_t stride) {
  Device& d = dev(cb);
  if (L().capturing()) {
    Lock lock(L().mutex());
    unrecordedDraw(d, cb, count);
  }
  d.vk.CmdDrawIndirect(cb, buffer, offset, count, stride);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndexedIndirect(VkCommandBuffer cb, VkBuffer buffer, VkDeviceSize offset,
                                                  uint32_t count, uint32_t stride) {
  Device& d = dev(cb);
  if (L().capturing()) {
    Lock lock(L().mutex());
    unrecordedDraw(d, cb, count);
  }
  d.vk.CmdDrawIndexedIndirect(cb, buffer, offset, count, stride);
}

VKAPI_ATTR void VKAPI_CALL CmdCopyBufferToImage(VkCommandBuffer cb, VkBuffer buffer, VkImage image, VkImageLayout layout,
                                                uint32_t count, const VkBufferImageCopy* regions) {
  Device& d = dev(cb);
  if (L().capturing()) {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) r->uploads.push_back({buffer, image, {regions, regions + count}});
  }
  d.vk.CmdCopyBufferToImage(cb, buffer, image, layout, count, regions);
}

// Writes into buffers the layer cannot read directly (device-local memory on a discrete GPU, filled
// from a staging buffer): recorded in order, and applied to the buffer's shadow when the command
// buffer is submitted (vk_frame.cpp), while the staging buffer still holds what they copy.
// `describe` fills in the write, given the destination's shadow.
template <typename Describe>
void followWrite(VkCommandBuffer cb, VkBuffer destination, Describe describe) {
  if (!L().capturing()) return;
  Device& d = dev(cb);
  Lock lock(L().mutex());
  Recording* r = recording(d, cb);
  BufferShadow* shadow = r ? L().shadow(d, destination) : nullptr;
  if (!shadow) return;
  Recording::BufferWrite write;
  write.destination = destination;
  describe(write, *shadow);
  r->buffer_writes.push_back(std::move(write));
}

VKAPI_ATTR void VKAPI_CALL CmdCopyBuffer(VkCommandBuffer cb, VkBuffer source, VkBuffer destination, uint32_t count,
                                         const VkBufferCopy* regions) {
  followWrite(cb, destination, [&](Recording::BufferWrite& w, const BufferShadow&) {
    w.source = source;
    w.regions.assign(regions, regions + count);
  });
  dev(cb).vk.CmdCopyBuffer(cb, source, destination, count, regions);
}

VKAPI_ATTR void VKAPI_CALL CmdCopyBuffer2(VkCommandBuffer cb, const VkCopyBufferInfo2* info) {
  followWrite(cb, info->dstBuffer, [&](Recording::BufferWrite& w, const BufferShadow&) {
    w.source = info->srcBuffer;
    for (uint32_t i = 0; i < info->regionCount; ++i)
      w.regions.push_back({info->pRegions[i].srcOffset, info->pRegions[i].dstOffset, info->pRegions[i].size});
  });
  dev(cb).vk.CmdCopyBuffer2(cb, info);
}

VKAPI_ATTR void VKAPI_CALL CmdUpdateBuffer(VkCommandBuffer cb, VkBuffer destination, VkDeviceSize offset,
                                           VkDeviceSize size, const void* data) {
  followWrite(cb, destination, [&](Recording::BufferWrite& w, const BufferShadow&) {
    w.offset = offset, w.size = size;
    w.data.assign(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + size);
  });
  dev(cb).vk.CmdUpdateBuffer(cb, destination, offset, size, data);
}

VKAPI_ATTR void VKAPI_CALL CmdFillBuffer(VkCommandBuffer cb, VkBuffer destination, VkDeviceSize offset, VkDeviceSize size,
                                         uint32_t word) {
  followWrite(cb, destination, [&](Recording::BufferWrite& w, const BufferShadow& shadow) {
    w.offset = offset;
    // VK_WHOLE_SIZE: to the end of the buffer, in whole words.
    w.size = size != VK_WHOLE_SIZE ? size : offset < shadow.size ? (shadow.size - offset) & ~VkDeviceSize{3} : 0;
    w.data.resize(4);
    std::memcpy(w.data.data(), &word, 4);
  });
  dev(cb).vk.CmdFillBuffer(cb, destination, offset, size, word);
}

// A copy from an image into a buffer: the layer does not read images, so the buffer's bytes from
// the lowest region's offset on become unknown in its shadow (rather than keep what was copied
// there before).
template <typename Region>
void forgetFromImage(VkCommandBuffer cb, VkBuffer buffer, uint32_t count, const Region* regions) {
  VkDeviceSize first = VK_WHOLE_SIZE;
  for (uint32_t i = 0; i < count; ++i) first = std::min(first, regions[i].bufferOffset);
  followWrite(cb, buffer, [&](Recording::BufferWrite& w, const BufferShadow& shadow) {
    w.offset = first;
    w.size = first < shadow.size ? shadow.size - first : 0;
  });
}

VKAPI_ATTR void VKAPI_CALL CmdCopyImageToBuffer(VkCommandBuffer cb, VkImage image, VkImageLayout layout, VkBuffer buffer,
                                                uint32_t count, const VkBufferImageCopy* regions) {
  forgetFromImage(cb, buffer, count, regions);
  dev(cb).vk.CmdCopyImageToBuffer(cb, image, layout, buffer, count, regions);
}

VKAPI_ATTR void VKAPI_CALL CmdCopyImageToBuffer2(VkCommandBuffer cb, const VkCopyImageToBufferInfo2* info) {
  forgetFromImage(cb, info->dstBuffer, info->regionCount, info->pRegions);
  dev(cb).vk.CmdCopyImageToBuffer2(cb, info);
}

VKAPI_ATTR void VKAPI_CALL CmdExecuteCommands(VkCommandBuffer cb, uint32_t count, const VkCommandBuffer* secondaries) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) r->executed.insert(r->executed.end(), secondaries, secondaries + count);
  }
  d.vk.CmdExecuteCommands(cb, count, secondaries);
}

// ---------------------------------------------------------------------------------------------
// Submission and presentation (the frame itself is built in vk_frame.cpp).

#define VIPER_VK_HOOKS(X)                                                                                      \
  X(GetDeviceQueue) X(GetDeviceQueue2) X(AllocateMemory) X(FreeMemory) X(MapMemory) X(UnmapMemory)             \
  X(CreateBuffer) X(DestroyBuffer) X(BindBufferMemory) X(BindBufferMemory2) X(CreateImage) X(DestroyImage)     \
  X(CreateImageView) X(DestroyImageView) X(CreateSwapchainKHR) X(DestroySwapchainKHR) X(CreateRenderPass)      \
  X(DestroyRenderPass) X(CreateFramebuffer) X(DestroyFramebuffer) X(CreateShaderModule) X(DestroyShaderModule) \
  X(CreatePipelineLayout) X(DestroyPipelineLayout) X(CreateDescriptorSetLayout) X(DestroyDescriptorSetLayout)  \
  X(AllocateDescriptorSets) X(UpdateDescriptorSets) X(CreateGraphicsPipelines) X(DestroyPipeline)              \
  X(BeginCommandBuffer) X(FreeCommandBuffers) X(CmdBeginRenderPass) X(CmdNextSubpass) X(CmdEndRenderPass)      \
  X(CmdBindPipeline) X(CmdBindVertexBuffers) X(CmdBindIndexBuffer) X(CmdBindDescriptorSets) X(CmdPushConstants) \
  X(CmdSetViewport) X(CmdDraw) X(CmdDrawIndexed) X(CmdDrawIndirect) X(CmdDrawIndexedIndirect)                  \
  X(CmdExecuteCommands) X(QueueSubmit) X(QueueSubmit2) X(QueuePresentKHR) X(DestroyDevice) X(CreateRenderPass2)  \
  X(CmdBeginRenderPass2) X(CmdNextSubpass2) X(CmdEndRenderPass2) X(CmdBeginRendering)            \
  X(CmdEndRendering) X(CmdCopyBufferToImage) X(CmdCopyBuffer) X(CmdCopyBuffer2) X(CmdUpdateBuffer) X(CmdFillBuffer) \
  X(CmdCopyImageToBuffer) X(CmdCopyImageToBuffer2)

PFN_vkVoidFunction deviceHook(const char* name) {
#define VIPER_VK_MATCH(fn) \
  if (std::strcmp(name, "vk" #fn) == 0) return reinterpret_cast<PFN_vkVoidFunction>(&fn);
  VIPER_VK_HOOKS(VIPER_VK_MATCH)
#undef VIPER_VK_MATCH
  // The extension's names of what Vulkan 1.3 made core.
  if (std::strcmp(name, "vkCmdBeginRenderingKHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CmdBeginRendering);
  if (std::strcmp(name, "vkCmdEndRenderingKHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CmdEndRendering);
  if (std::strcmp(name, "vkQueueSubmit2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&QueueSubmit2);
  if (std::strcmp(name, "vkCreateRenderPass2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CreateRenderPass2);
  if (std::strcmp(name, "vkCmdBeginRenderPass2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CmdBeginRenderPass2);
  if (std::strcmp(name, "vkCmdNextSubpass2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CmdNextSubpass2);
  if (std::strcmp(name, "vkCmdEndRenderPass2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CmdEndRenderPass2);
  if (std::strcmp(name, "vkCmdCopyBuffer2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CmdCopyBuffer2);
  if (std::strcmp(name, "vkCmdCopyImageToBuffer2KHR") == 0)
    return reinterpret_cast<PFN_vkVoidFunction>(&CmdCopyImageToBuffer2);
  return nullptr;
}

}  // namespace

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* name) {
  if (PFN_vkVoidFunction f = deviceHook(name)) return f;
  Layer::Device* d = L().device(dispatchKey(device));
  return d ? d->next_gdpa(device, name) : nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char* name) {
  if (std::strcmp(name, "vkGetInstanceProcAddr") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&GetInstanceProcAddr);
  if (std::strcmp(name, "vkCreateInstance") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CreateInstance);
  if (std::strcmp(name, "vkDestroyInstance") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&DestroyInstance);
  if (std::strcmp(name, "vkCreateDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CreateDevice);
  if (std::strcmp(name, "vkGetDeviceProcAddr") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
  if (PFN_vkVoidFunction f = deviceHook(name)) return f;
  if (!instance) return nullptr;
  InstanceData* d = L().instance(dispatchKey(instance));
  return d ? d->next_gipa(instance, name) : nullptr;
}

}  // namespace vulkan
}  // namespace capture
}  // namespace viper

VIPER_VK_EXPORT VKAPI_ATTR VkResult VKAPI_CALL vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface* v) {
  if (v->loaderLayerInterfaceVersion > 2) v->loaderLayerInterfaceVersion = 2;
  v->pfnGetInstanceProcAddr = &viper::capture::vulkan::GetInstanceProcAddr;
  v->pfnGetDeviceProcAddr = &viper::capture::vulkan::GetDeviceProcAddr;
  v->pfnGetPhysicalDeviceProcAddr = nullptr;
  return VK_SUCCESS;
}

VIPER_VK_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL viper_vkGetInstanceProcAddr(VkInstance instance, const char* name) {
  return viper::capture::vulkan::GetInstanceProcAddr(instance, name);
}

VIPER_VK_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL viper_vkGetDeviceProcAddr(VkDevice device, const char* name) {
  return viper::capture::vulkan::GetDeviceProcAddr(device, name);
}
