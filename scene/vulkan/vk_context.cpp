#include "vk_context.h"

#include <vulkan/vulkan_xcb.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace viper {
namespace scene {
namespace vk {
namespace {

bool hasExtension(const std::vector<VkExtensionProperties>& extensions, const char* name) {
  return std::any_of(extensions.begin(), extensions.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice device) {
  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  return extensions;
}

std::string versionText(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." + std::to_string(VK_API_VERSION_MINOR(version)) + "." +
         std::to_string(VK_API_VERSION_PATCH(version));
}

}  // namespace

std::string resultName(VkResult result) {
  switch (result) {
#define VIPER_VK_RESULT(name) \
  case name: return #name;
    VIPER_VK_RESULT(VK_SUCCESS)
    VIPER_VK_RESULT(VK_NOT_READY)
    VIPER_VK_RESULT(VK_TIMEOUT)
    VIPER_VK_RESULT(VK_INCOMPLETE)
    VIPER_VK_RESULT(VK_SUBOPTIMAL_KHR)
    VIPER_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    VIPER_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    VIPER_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    VIPER_VK_RESULT(VK_ERROR_DEVICE_LOST)
    VIPER_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    VIPER_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    VIPER_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    VIPER_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    VIPER_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    VIPER_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    VIPER_VK_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    VIPER_VK_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    VIPER_VK_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
#undef VIPER_VK_RESULT
    default: return "VkResult " + std::to_string(static_cast<int>(result));
  }
}

void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS) throw VulkanError(std::string(what) + " failed: " + resultName(result));
}

VkImageView createImageView(VkDevice device, VkImage image, VkFormat format, VkImageAspectFlags aspect) {
  VkImageViewCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  info.image = image;
  info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  info.format = format;
  info.subresourceRange = {aspect, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  check(vkCreateImageView(device, &info, nullptr, &view), "vkCreateImageView");
  return view;
}

Context::Context(uint32_t width, uint32_t height, bool dynamic_rendering, bool vulkan13, bool headless)
    : headless_(headless) {
  try {
    if (!headless_) openWindow(width, height);
    createInstance();
    pickDevice(dynamic_rendering, vulkan13);
  } catch (...) {
    release();
    throw;
  }
}

Context::~Context() { release(); }

void Context::release() {
  if (one_time_pool_) vkDestroyCommandPool(device_, one_time_pool_, nullptr);
  if (device_) vkDestroyDevice(device_, nullptr);
  if (surface_) vkDestroySurfaceKHR(instance_, surface_, nullptr);
  if (instance_) vkDestroyInstance(instance_, nullptr);
  if (window_) xcb_destroy_window(connection_, window_);
  if (connection_) xcb_disconnect(connection_);
  one_time_pool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  surface_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
  window_ = 0;
  connection_ = nullptr;
}

void Context::openWindow(uint32_t width, uint32_t height) {
  int screen_number = 0;
  connection_ = xcb_connect(nullptr, &screen_number);
  if (xcb_connection_has_error(connection_)) {
    const char* display = std::getenv("DISPLAY");
    throw std::runtime_error((display ? std::string("cannot open the X display '") + display + "' (DISPLAY)"
                                      : std::string("DISPLAY is not set")) +
                             ": vk_test_scene presents to an X window; start an X server, e.g. "
                             "`Xvfb :57 -screen 0 1024x768x24 &`, and set DISPLAY=:57 (or draw without one: "
                             "--headless)");
  }
  xcb_screen_iterator_t it = xcb_setup_roots_iterator(xcb_get_setup(connection_));
  for (int i = 0; i < screen_number && it.rem > 0; ++i) xcb_screen_next(&it);
  if (it.rem == 0) throw std::runtime_error("the X display has no screen " + std::to_string(screen_number));
  const xcb_screen_t* screen = it.data;
  window_ = xcb_generate_id(connection_);
  const uint32_t values[] = {screen->black_pixel};
  xcb_create_window(connection_, XCB_COPY_FROM_PARENT, window_, screen->root, 0, 0, static_cast<uint16_t>(width),
                    static_cast<uint16_t>(height), 0, XCB_WINDOW_CLASS_INPUT_OUTPUT, screen->root_visual,
                    XCB_CW_BACK_PIXEL, values);
  const char title[] = "vk_test_scene";
  xcb_change_property(connection_, XCB_PROP_MODE_REPLACE, window_, XCB_ATOM_WM_NAME, XCB_ATOM_STRING, 8,
                      sizeof(title) - 1, title);
  xcb_map_window(connection_, window_);
  xcb_flush(connection_);
}

void Context::createInstance() {
  uint32_t count = 0;
  check(vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr), "vkEnumerateInstanceExtensionProperties");
  std::vector<VkExtensionProperties> extensions(count);
  check(vkEnumerateInstanceExtensionProperties(nullptr, &count, extensions.data()),
        "vkEnumerateInstanceExtensionProperties");
  // Headless, no extension at all: nothing is shown, so nothing needs a surface.
  const std::vector<const char*> names =
      headless_ ? std::vector<const char*>{}
                : std::vector<const char*>{VK_KHR_SURFACE_EXTENSION_NAME, VK_KHR_XCB_SURFACE_EXTENSION_NAME};
  for (const char* name : names)
    if (!hasExtension(extensions, name))
      throw std::runtime_error(std::string("no Vulkan device: the Vulkan loader offers no ") + name +
                               " (is a Vulkan driver such as mesa-vulkan-drivers installed?)");

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "vk_test_scene";
  app.applicationVersion = 1;
  app.pEngineName = "viper";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledExtensionCount = static_cast<uint32_t>(names.size());
  info.ppEnabledExtensionNames = names.data();
  const VkResult result = vkCreateInstance(&info, nullptr, &instance_);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw std::runtime_error("no Vulkan device: vkCreateInstance found no driver (VK_ERROR_INCOMPATIBLE_DRIVER)");
  check(result, "vkCreateInstance");
  if (headless_) return;

  VkXcbSurfaceCreateInfoKHR surface{VK_STRUCTURE_TYPE_XCB_SURFACE_CREATE_INFO_KHR};
  surface.connection = connection_;
  surface.window = window_;
  check(vkCreateXcbSurfaceKHR(instance_, &surface, nullptr, &surface_), "vkCreateXcbSurfaceKHR");
}

void Context::pickDevice(bool dynamic_rendering, bool vulkan13) {
  uint32_t count = 0;
  const VkResult enumerated = vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  if (enumerated == VK_ERROR_INITIALIZATION_FAILED)
    throw std::runtime_error("no Vulkan device: vkEnumeratePhysicalDevices failed (VK_ERROR_INITIALIZATION_FAILED): "
                             "no installed driver could open a device");
  check(enumerated, "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  check(vkEnumeratePhysicalDevices(instance_, &count, devices.data()), "vkEnumeratePhysicalDevices");
  std::string rejected;
  bool dynamic_rendering_extension = false;
  for (VkPhysicalDevice candidate : devices) {
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(candidate, &properties);
    const std::vector<VkExtensionProperties> extensions = deviceExtensions(candidate);
    auto reject = [&](const std::string& why) { rejected += std::string("; ") + properties.deviceName + ": " + why; };
    if (properties.apiVersion < VK_API_VERSION_1_2) {
      reject("Vulkan " + versionText(properties.apiVersion) + " < 1.2");
      continue;
    }
    if (vulkan13 && properties.apiVersion < VK_API_VERSION_1_3) {
      reject("Vulkan " + versionText(properties.apiVersion) + " < 1.3 (--render-pass2)");
      continue;
    }
    if (!headless_ && !hasExtension(extensions, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) {
      reject("no VK_KHR_swapchain");
      continue;
    }
    const bool core_rendering = properties.apiVersion >= VK_API_VERSION_1_3;
    if (dynamic_rendering) {
      VkPhysicalDeviceDynamicRenderingFeatures rendering{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES};
      VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
      features.pNext = &rendering;
      if (core_rendering || hasExtension(extensions, VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME))
        vkGetPhysicalDeviceFeatures2(candidate, &features);
      if (!rendering.dynamicRendering) {
        reject("no dynamic rendering (Vulkan 1.3 or VK_KHR_dynamic_rendering)");
        continue;
      }
    }
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, families.data());
    for (uint32_t f = 0; f < family_count && !physical_; ++f) {
      VkBool32 presents = headless_ ? VK_TRUE : VK_FALSE;  // headless: nothing to present to
      if (!headless_)
        check(vkGetPhysicalDeviceSurfaceSupportKHR(candidate, f, surface_, &presents),
              "vkGetPhysicalDeviceSurfaceSupportKHR");
      if ((families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) && presents) {
        physical_ = candidate;
        queue_family_ = f;
        properties_ = properties;
        dynamic_rendering_extension = dynamic_rendering && !core_rendering;
      }
    }
    if (physical_) break;
    reject(headless_ ? "no graphics queue" : "no queue that draws and presents to the window");
  }
  if (!physical_)
    throw std::runtime_error(std::string(headless_ ? "no Vulkan device draws (headless)"
                                                   : "no Vulkan device draws and presents to the X window") +
                             " (" + std::to_string(count) + " device(s)" + rejected + ")");
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  std::vector<const char*> names;
  if (!headless_) names.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  if (dynamic_rendering_extension) names.push_back(VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME);
  VkPhysicalDeviceDynamicRenderingFeatures rendering{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES};
  rendering.dynamicRendering = VK_TRUE;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = dynamic_rendering ? &rendering : nullptr;
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  if (vulkan13) {
    features12.imagelessFramebuffer = VK_TRUE;
    features12.pNext = &features13;
    features13.synchronization2 = VK_TRUE;
    info.pNext = &features12;
  }
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  info.enabledExtensionCount = static_cast<uint32_t>(names.size());
  info.ppEnabledExtensionNames = names.data();
  check(vkCreateDevice(physical_, &info, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

  if (dynamic_rendering) {
    const bool core = !dynamic_rendering_extension;
    cmdBeginRendering = reinterpret_cast<PFN_vkCmdBeginRenderingKHR>(
        vkGetDeviceProcAddr(device_, core ? "vkCmdBeginRendering" : "vkCmdBeginRenderingKHR"));
    cmdEndRendering = reinterpret_cast<PFN_vkCmdEndRenderingKHR>(
        vkGetDeviceProcAddr(device_, core ? "vkCmdEndRendering" : "vkCmdEndRenderingKHR"));
    if (!cmdBeginRendering || !cmdEndRendering)
      throw std::runtime_error("vkGetDeviceProcAddr found no vkCmdBeginRendering/vkCmdEndRendering");
  }

  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = queue_family_;
  check(vkCreateCommandPool(device_, &pool, nullptr, &one_time_pool_), "vkCreateCommandPool");
}

std::string Context::description() const {
  return std::string(properties_.deviceName) + ", Vulkan " + versionText(properties_.apiVersion);
}

uint32_t Context::memoryType(uint32_t type_bits, VkMemoryPropertyFlags properties) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & properties) == properties) return i;
  throw std::runtime_error("the Vulkan device has no memory type with properties 0x" + std::to_string(properties));
}

VkDeviceMemory Context::allocate(const VkMemoryRequirements& needs, VkMemoryPropertyFlags properties) const {
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  info.allocationSize = needs.size;
  info.memoryTypeIndex = memoryType(needs.memoryTypeBits, properties);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  check(vkAllocateMemory(device_, &info, nullptr, &memory), "vkAllocateMemory");
  return memory;
}

Buffer Context::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags properties) const {
  Buffer b;
  b.size = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(device_, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements needs;
  vkGetBufferMemoryRequirements(device_, b.buffer, &needs);
  try {
    b.memory = allocate(needs, properties);
    check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
    if (properties & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
      check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  } catch (...) {
    destroy(b);
    throw;
  }
  return b;
}

void Context::destroy(Buffer& b) const {
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);  // also unmaps
  b = Buffer{};
}

Image Context::createImage(uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
                           VkImageAspectFlags aspect) const {
  Image image;
  image.format = format;
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(vkCreateImage(device_, &info, nullptr, &image.image), "vkCreateImage");
  VkMemoryRequirements needs;
  vkGetImageMemoryRequirements(device_, image.image, &needs);
  try {
    image.memory = allocate(needs, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    check(vkBindImageMemory(device_, image.image, image.memory, 0), "vkBindImageMemory");
    image.view = createImageView(device_, image.image, format, aspect);
  } catch (...) {
    destroy(image);
    throw;
  }
  return image;
}

void Context::destroy(Image& image) const {
  if (image.view) vkDestroyImageView(device_, image.view, nullptr);
  if (image.image) vkDestroyImage(device_, image.image, nullptr);
  if (image.memory) vkFreeMemory(device_, image.memory, nullptr);
  image = Image{};
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) const {
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = one_time_pool_;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer commands = VK_NULL_HANDLE;
  check(vkAllocateCommandBuffers(device_, &allocate, &commands), "vkAllocateCommandBuffers");
  try {
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(commands, &begin), "vkBeginCommandBuffer");
    record(commands);
    check(vkEndCommandBuffer(commands), "vkEndCommandBuffer");
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    check(vkQueueSubmit(queue_, 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
    check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
  } catch (...) {
    vkFreeCommandBuffers(device_, one_time_pool_, 1, &commands);
    throw;
  }
  vkFreeCommandBuffers(device_, one_time_pool_, 1, &commands);
}

Swapchain::Swapchain(const Context& context, uint32_t width, uint32_t height, bool readable) : context_(context) {
  try {
    if (context.headless()) createHeadlessImages(width, height);
    else createSwapchain(width, height, readable);
  } catch (...) {
    release();
    throw;
  }
}

void Swapchain::createHeadlessImages(uint32_t width, uint32_t height) {
  // What an offscreen renderer draws into: RGBA8, and readable by a copy whether or not frames are dumped.
  format_ = VK_FORMAT_R8G8B8A8_UNORM;
  extent_ = {width, height};
  usage_ = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  for (uint32_t i = 0; i < kHeadlessImages; ++i) {
    owned_.push_back(context_.createImage(width, height, format_, usage_, VK_IMAGE_ASPECT_COLOR_BIT));
    images_.push_back(owned_.back().image);
    views_.push_back(owned_.back().view);
  }
}

void Swapchain::createSwapchain(uint32_t width, uint32_t height, bool readable) {
  VkPhysicalDevice physical = context_.physicalDevice();
  VkSurfaceKHR surface = context_.surface();
  VkSurfaceCapabilitiesKHR caps;
  check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface, &caps), "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  extent_ = caps.currentExtent.width != UINT32_MAX ? caps.currentExtent : VkExtent2D{width, height};
  if (extent_.width != width || extent_.height != height)
    throw std::runtime_error("the window is " + std::to_string(extent_.width) + "x" + std::to_string(extent_.height) +
                             ", not the " + std::to_string(width) + "x" + std::to_string(height) + " asked for");

  uint32_t count = 0;
  check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr), "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()),
        "vkGetPhysicalDeviceSurfaceFormatsKHR");
  // UNORM, not SRGB: test_scene's framebuffer stores the shader's values as they are.
  VkColorSpaceKHR color_space = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const VkSurfaceFormatKHR& f : formats)
      if (format_ == VK_FORMAT_UNDEFINED && f.format == wanted) {
        format_ = f.format;
        color_space = f.colorSpace;
      }
  if (format_ == VK_FORMAT_UNDEFINED) throw std::runtime_error("the window offers no B8G8R8A8_UNORM or R8G8B8A8_UNORM swapchain");

  check(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &count, nullptr),
        "vkGetPhysicalDeviceSurfacePresentModesKHR");
  std::vector<VkPresentModeKHR> modes(count);
  check(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &count, modes.data()),
        "vkGetPhysicalDeviceSurfacePresentModesKHR");
  if (std::find(modes.begin(), modes.end(), VK_PRESENT_MODE_IMMEDIATE_KHR) != modes.end())
    present_mode_ = VK_PRESENT_MODE_IMMEDIATE_KHR;

  usage_ = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | (readable ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
  if ((caps.supportedUsageFlags & usage_) != usage_)
    throw std::runtime_error("the window's swapchain images cannot be drawn into" +
                             std::string(readable ? " and read back (--dump-dir)" : ""));
  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface;
  info.minImageCount = caps.maxImageCount == 0 ? caps.minImageCount + 1 : std::min(caps.minImageCount + 1, caps.maxImageCount);
  info.imageFormat = format_;
  info.imageColorSpace = color_space;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  info.imageUsage = usage_;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : static_cast<VkCompositeAlphaFlagBitsKHR>(caps.supportedCompositeAlpha &
                                                                       -caps.supportedCompositeAlpha);
  info.presentMode = present_mode_;
  info.clipped = VK_TRUE;
  VkDevice device = context_.device();
  check(vkCreateSwapchainKHR(device, &info, nullptr, &swapchain_), "vkCreateSwapchainKHR");
  check(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr), "vkGetSwapchainImagesKHR");
  images_.resize(count);
  check(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()), "vkGetSwapchainImagesKHR");
  for (VkImage image : images_) views_.push_back(createImageView(device, image, format_, VK_IMAGE_ASPECT_COLOR_BIT));
}

Swapchain::~Swapchain() { release(); }

void Swapchain::release() {
  // Headless, the views belong to the owned images, destroyed with them.
  if (owned_.empty())
    for (VkImageView view : views_) vkDestroyImageView(context_.device(), view, nullptr);
  for (Image& image : owned_) context_.destroy(image);
  owned_.clear();
  views_.clear();
  images_.clear();
  if (swapchain_) vkDestroySwapchainKHR(context_.device(), swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
}

VkImageLayout Swapchain::finalLayout() const {
  return headless() ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
}

uint32_t Swapchain::acquire(VkSemaphore signal) const {
  if (headless()) {
    const uint32_t index = next_;
    next_ = (next_ + 1) % static_cast<uint32_t>(images_.size());
    return index;
  }
  uint32_t index = 0;
  const VkResult result = vkAcquireNextImageKHR(context_.device(), swapchain_, UINT64_MAX, signal, VK_NULL_HANDLE, &index);
  if (result != VK_SUBOPTIMAL_KHR) check(result, "vkAcquireNextImageKHR");
  return index;
}

void Swapchain::present(uint32_t index, VkSemaphore wait, VkFence done) const {
  if (headless()) {
    check(vkWaitForFences(context_.device(), 1, &done, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    return;
  }
  VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &wait;
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain_;
  info.pImageIndices = &index;
  const VkResult result = vkQueuePresentKHR(context_.queue(), &info);
  if (result != VK_SUBOPTIMAL_KHR) check(result, "vkQueuePresentKHR");
}

}  // namespace vk
}  // namespace scene
}  // namespace viper
