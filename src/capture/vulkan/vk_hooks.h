// What the Vulkan layer's hook files share: the hooks themselves (declared from Vulkan's own
// function-pointer types: a definition with another signature leaves the hook undefined, and the
// layer does not link), the list GetDeviceProcAddr answers from, and small helpers. The hooks are
// in vk_hooks.cpp (instance and device, the dispatch), vk_resources.cpp (memory, buffers, images,
// swapchains), vk_passes.cpp (render passes, framebuffers, the id attachment and the copies at a
// pass's end), vk_pipelines.cpp (shaders, layouts, descriptors, pipelines), vk_commands.cpp
// (command buffers: binds, draws, copies) and vk_frame.cpp (submission and presentation).
#pragma once

#include "capture_layer.h"

#include <type_traits>
#include <vector>

namespace viper {
namespace capture {
namespace vulkan {

using Device = Layer::Device;
using Lock = std::lock_guard<std::mutex>;

inline Layer& L() { return Layer::get(); }
template <typename T>
Device& dev(T handle) {
  return *L().device(dispatchKey(handle));
}

constexpr VkFormat kIdFormat = VK_FORMAT_R32G32B32A32_UINT;

inline bool isReadableColorFormat(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_SRGB;
}

inline bool isDepthFormat(VkFormat f) {
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

// A driver call's result `r`; if it succeeded, `record` then notes under the lock what the call
// made or changed.
template <typename Record>
VkResult recordOnSuccess(VkResult r, Record record) {
  if (r == VK_SUCCESS) {
    Lock lock(L().mutex());
    record();
  }
  return r;
}

/// The device-level hooks, by their Vulkan name less `vk` (GetDeviceProcAddr answers with these).
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

// Declared with the types of Vulkan's function pointers (their calling convention included).
#define VIPER_VK_DECLARE_HOOK(fn) std::remove_pointer_t<PFN_vk##fn> fn;
VIPER_VK_HOOKS(VIPER_VK_DECLARE_HOOK)
VIPER_VK_DECLARE_HOOK(CreateInstance)
VIPER_VK_DECLARE_HOOK(DestroyInstance)
VIPER_VK_DECLARE_HOOK(CreateDevice)
VIPER_VK_DECLARE_HOOK(GetDeviceProcAddr)
VIPER_VK_DECLARE_HOOK(GetInstanceProcAddr)
#undef VIPER_VK_DECLARE_HOOK

// Across the hook files.
Recording* recording(Device& d, VkCommandBuffer cb);
IdImage makeIdImage(Device& d, uint32_t width, uint32_t height, uint32_t layers);
void destroyIdImage(Device& d, const IdImage& ids);

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
