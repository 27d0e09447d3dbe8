// The Vulkan plumbing of vk_test_scene: an X window (xcb), the instance, the device and its queue,
// the window's swapchain (or, headless, images of its own), and the buffer/image helpers the renderer
// builds on. No scene knowledge.
#pragma once

#include <vulkan/vulkan.h>
#include <xcb/xcb.h>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace viper {
namespace scene {
namespace vk {

/// A failed Vulkan call; the message names the call and its VkResult.
class VulkanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws VulkanError("<what>: VK_ERROR_...") unless `result` is VK_SUCCESS.
void check(VkResult result, const char* what);

/// VK_SUCCESS, VK_ERROR_OUT_OF_DATE_KHR, ... (the number for unknown codes).
std::string resultName(VkResult result);

/// A buffer with its own memory; `mapped` is the persistent mapping of host-visible memory, else null.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

/// A 2D image with its own device-local memory and one view of all of it.
struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
};

/// Instance, X window and surface, physical and logical device, one graphics+present queue.
class Context {
 public:
  /// Opens a `width` x `height` window on $DISPLAY and picks the first device that can draw and
  /// present to it. Throws std::runtime_error with what to do if there is no X display, no Vulkan
  /// driver or no device that presents to X; `dynamic_rendering` also requires Vulkan 1.3 or
  /// VK_KHR_dynamic_rendering.
  /// `vulkan13`: the device must offer Vulkan 1.3, with imagelessFramebuffer and synchronization2
  /// enabled (--render-pass2).
  /// `headless`: no X connection, window or surface, and none of VK_KHR_surface, VK_KHR_xcb_surface
  /// or VK_KHR_swapchain asked for; the first device with a graphics queue is picked.
  Context(uint32_t width, uint32_t height, bool dynamic_rendering, bool vulkan13 = false, bool headless = false);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queue_family_; }
  /// The window's surface; null when headless.
  VkSurfaceKHR surface() const { return surface_; }
  bool headless() const { return headless_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  /// "llvmpipe (LLVM 15.0.6, 256 bits), Vulkan 1.3.230".
  std::string description() const;

  /// vkCmdBeginRendering / vkCmdEndRendering (core or KHR); null unless dynamic rendering was asked for.
  PFN_vkCmdBeginRenderingKHR cmdBeginRendering = nullptr;
  PFN_vkCmdEndRenderingKHR cmdEndRendering = nullptr;

  /// A buffer in memory with `properties`; host-visible memory is mapped for the buffer's lifetime.
  Buffer createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags properties) const;
  void destroy(Buffer& buffer) const;
  /// A device-local 2D image of one mip level and layer, with a view of `aspect`.
  Image createImage(uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
                    VkImageAspectFlags aspect) const;
  void destroy(Image& image) const;
  /// Records commands with `record` into a one-time command buffer, submits it and waits.
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record) const;

 private:
  void release();
  void openWindow(uint32_t width, uint32_t height);
  void createInstance();
  void pickDevice(bool dynamic_rendering, bool vulkan13);
  uint32_t memoryType(uint32_t type_bits, VkMemoryPropertyFlags properties) const;
  /// Memory for `needs` with `properties` (throws std::runtime_error).
  VkDeviceMemory allocate(const VkMemoryRequirements& needs, VkMemoryPropertyFlags properties) const;

  bool headless_ = false;
  xcb_connection_t* connection_ = nullptr;
  xcb_window_t window_ = 0;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDevice device_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool one_time_pool_ = VK_NULL_HANDLE;
};

/// The window's swapchain: its images, one view each, acquire and present. With a headless context,
/// its stand-in: a ring of plain images of its own that nothing presents, so that the renderer draws
/// the same way into either.
class Swapchain {
 public:
  /// A swapchain of the window's size in B8G8R8A8_UNORM (or R8G8B8A8_UNORM), IMMEDIATE present
  /// mode where offered, else FIFO. `readable` adds TRANSFER_SRC usage (frame dumps).
  /// Headless: kHeadlessImages device-local `width` x `height` R8G8B8A8_UNORM images, usable as
  /// colour attachments and transfer sources whether or not `readable`.
  Swapchain(const Context& context, uint32_t width, uint32_t height, bool readable);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  VkFormat format() const { return format_; }
  VkExtent2D extent() const { return extent_; }
  VkPresentModeKHR presentMode() const { return present_mode_; }
  bool headless() const { return context_.headless(); }
  /// The usage the images were made with (imageless framebuffers describe their attachments by it).
  VkImageUsageFlags usage() const { return usage_; }
  /// The layout a frame leaves its image in: PRESENT_SRC_KHR, or (headless, where that layout does
  /// not exist without VK_KHR_swapchain) TRANSFER_SRC_OPTIMAL, ready for a frame dump's copy.
  VkImageLayout finalLayout() const;
  size_t imageCount() const { return images_.size(); }
  VkImage image(size_t i) const { return images_[i]; }
  VkImageView view(size_t i) const { return views_[i]; }
  /// Whether the format stores blue first (the dump swaps it back).
  bool bgr() const { return format_ == VK_FORMAT_B8G8R8A8_UNORM; }

  /// Index of the next image; `signal` is signalled when it may be written. Throws VulkanError
  /// (the window changed and the swapchain is out of date, or the device was lost).
  /// Headless: the next image of the ring, at once; `signal` must be null (nothing to wait for).
  uint32_t acquire(VkSemaphore signal) const;
  /// Presents image `index` once `wait` is signalled; `done` (the fence of the frame's submission)
  /// is not used. Headless, there is nothing to present to: `wait` must be null, and this waits for
  /// `done`, so that the frame is finished before the next one begins.
  void present(uint32_t index, VkSemaphore wait, VkFence done) const;

  /// Images of the headless ring: two, as many as the renderer's frames in flight.
  static constexpr uint32_t kHeadlessImages = 2;

 private:
  void createSwapchain(uint32_t width, uint32_t height, bool readable);
  void createHeadlessImages(uint32_t width, uint32_t height);
  void release();

  const Context& context_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{};
  VkPresentModeKHR present_mode_ = VK_PRESENT_MODE_FIFO_KHR;
  VkImageUsageFlags usage_ = 0;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<Image> owned_;   // headless: the images and views above, with their memory
  mutable uint32_t next_ = 0;  // headless: the ring's next image (acquire is const, as for a swapchain)
};

/// A view of all of a 2D image (one level, one layer).
VkImageView createImageView(VkDevice device, VkImage image, VkFormat format, VkImageAspectFlags aspect);

}  // namespace vk
}  // namespace scene
}  // namespace viper
