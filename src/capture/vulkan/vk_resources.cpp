// The Vulkan layer's hooks of memory, buffers, images and swapchains: what it follows of them
// (mappings, usage, formats, upload keys), and the usage it adds for its read-back.
#include "vk_hooks.h"

namespace viper {
namespace capture {
namespace vulkan {

// ---------------------------------------------------------------------------------------------
// Memory, buffers, images.

VKAPI_ATTR VkResult VKAPI_CALL AllocateMemory(VkDevice device, const VkMemoryAllocateInfo* info,
                                              const VkAllocationCallbacks* alloc, VkDeviceMemory* out) {
  Device& d = dev(device);
  return recordOnSuccess(d.vk.AllocateMemory(device, info, alloc, out), [&] {
    MemoryInfo m;
    m.size = info->allocationSize;
    m.type = info->memoryTypeIndex;
    const VkMemoryPropertyFlags flags = d.memory_properties.memoryTypes[m.type].propertyFlags;
    m.host_visible = flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
    m.coherent = flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    d.memories[*out] = m;
  });
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
  return recordOnSuccess(d.vk.CreateBuffer(device, info, alloc, out), [&] { d.buffers[*out].size = info->size; });
}

VKAPI_ATTR void VKAPI_CALL DestroyBuffer(VkDevice device, VkBuffer buffer, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(buffer, d.buffers, d.shadows);
  d.vk.DestroyBuffer(device, buffer, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory(VkDevice device, VkBuffer buffer, VkDeviceMemory memory,
                                                VkDeviceSize offset) {
  Device& d = dev(device);
  return recordOnSuccess(d.vk.BindBufferMemory(device, buffer, memory, offset), [&] {
    d.buffers[buffer].memory = memory;
    d.buffers[buffer].memory_offset = offset;
  });
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory2(VkDevice device, uint32_t count, const VkBindBufferMemoryInfo* infos) {
  Device& d = dev(device);
  return recordOnSuccess(d.vk.BindBufferMemory2(device, count, infos), [&] {
    for (uint32_t i = 0; i < count; ++i) {
      d.buffers[infos[i].buffer].memory = infos[i].memory;
      d.buffers[infos[i].buffer].memory_offset = infos[i].memoryOffset;
    }
  });
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
  return recordOnSuccess(d.vk.CreateImageView(device, info, alloc, out),
                         [&] { d.views[*out] = ImageViewInfo{info->image, info->format}; });
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

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
