// The Vulkan layer's entry points: instance and device creation (dispatch chains) and the
// dispatch of every hook (vk_hooks.h lists them; capture_layer.h says what the layer changes).
#include "vk_hooks.h"

#include <cstring>

#define VIPER_VK_EXPORT extern "C" __attribute__((visibility("default")))

namespace viper {
namespace capture {
namespace vulkan {

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

namespace {

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
