// The Vulkan capture layer (VK_LAYER_VIPER_capture): a loader layer that records what a Vulkan
// program draws into the same capture stream the OpenGL layer writes. Enabled by `capture` for
// every program (VK_INSTANCE_LAYERS); a pass-through when VIPER_CAPTURE_OUTPUT is not set.
//
// What it changes in the program's objects, none of which the program can see in its image:
// - render passes whose subpasses have a single-sampled depth attachment get one more colour
//   attachment of the layer's (RGBA32UI, cleared to 0) in those subpasses, and their depth is
//   stored; framebuffers of them get the layer's image for it;
// - pipeline layouts get 8 bytes of push constants past the program's own, for the fragment stage;
// - the fragment shaders of pipelines drawn in such subpasses write (recording, draw, primitive)
//   to the id attachment (spirv_module.h), and their blend state gets the attachment;
// - swapchain images and depth images can be read back (TRANSFER_SRC added to their usage);
// - the device gets the geometryShader feature (gl_PrimitiveID in fragment shaders) if it has it.
#pragma once

#include "vk_state.h"
#include "viper/capture/capture_profile.h"
#include "viper/capture/capture_stream.h"

namespace viper {
namespace capture {
namespace vulkan {

class FrameSinkHandle;

/// The layer's state: every object it follows, per device. Methods take the lock themselves.
class Layer {
 public:
  static Layer& get();

  bool capturing() const { return enabled_; }
  std::mutex& mutex() { return mutex_; }

  // Instances and devices.
  InstanceData* instance(void* key);
  void addInstance(VkInstance instance, PFN_vkGetInstanceProcAddr gipa);
  void removeInstance(VkInstance instance);
  struct Device;
  Device* device(void* key);
  Device* addDevice(VkPhysicalDevice physical, VkDevice device, PFN_vkGetDeviceProcAddr gdpa,
                    PFN_vkSetDeviceLoaderData set_loader_data);
  void removeDevice(VkDevice device);

  struct Device {
    VkDevice device = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    InstanceData* instance = nullptr;
    PFN_vkGetDeviceProcAddr next_gdpa = nullptr;
    PFN_vkSetDeviceLoaderData set_loader_data = nullptr;
    DeviceTable vk;
    VkPhysicalDeviceMemoryProperties memory_properties{};
    VkPhysicalDeviceLimits limits{};
    bool primitive_id = false;  ///< geometryShader enabled: fragment shaders may read gl_PrimitiveID

    std::unordered_map<VkQueue, uint32_t> queue_families;
    std::unordered_map<VkDeviceMemory, MemoryInfo> memories;
    std::unordered_map<VkBuffer, BufferInfo> buffers;
    /// Shadows of the buffers written by copies that the layer cannot read directly (all copy
    /// destinations with VIPER_VULKAN_SHADOW_COPIES); freed with their buffer.
    std::unordered_map<VkBuffer, BufferShadow> shadows;
    std::unordered_map<VkImage, DepthImage> depth_images;
    /// The layer's id images for dynamic rendering, one per size.
    std::map<std::pair<uint32_t, uint32_t>, IdImage> rendering_ids;
    std::unordered_map<VkImageView, ImageViewInfo> views;
    /// Every image's usage as created (the layer's additions included), swapchain images too.
    std::unordered_map<VkImage, VkImageUsageFlags> image_usage;
    std::unordered_map<VkImage, VkFormat> image_formats;
    /// Content keys of images the program uploaded (of their first mip level's bytes).
    std::unordered_map<VkImage, uint64_t> image_keys;
    std::unordered_map<VkRenderPass, RenderPassInfo> render_passes;
    std::unordered_map<VkFramebuffer, FramebufferInfo> framebuffers;
    std::unordered_map<VkShaderModule, std::vector<uint32_t>> modules;
    std::unordered_map<VkPipelineLayout, LayoutInfo> layouts;
    std::unordered_map<VkDescriptorSetLayout, DescriptorSetLayoutInfo> set_layouts;
    std::unordered_map<VkDescriptorSet, DescriptorSetInfo> sets;
    std::unordered_map<VkPipeline, PipelineInfo> pipelines;
    std::unordered_map<VkSwapchainKHR, SwapchainInfo> swapchains;
    std::unordered_map<VkCommandBuffer, std::shared_ptr<Recording>> recordings;
    /// Recordings submitted since the last present, in submission order.
    std::vector<std::shared_ptr<Recording>> frame;
    /// Recordings replaced while a frame still held them: their buffers are freed after the frame.
    std::vector<std::shared_ptr<Recording>> retired;
    /// The id words of draws whose push constants are full: one slot (stride bytes) per draw in a
    /// host-visible uniform buffer, bound at set `id_set` with the slot's dynamic offset.
    struct IdBuffer {
      VkDescriptorSetLayout layout = VK_NULL_HANDLE, empty = VK_NULL_HANDLE;
      VkDescriptorPool pool = VK_NULL_HANDLE;
      VkDescriptorSet set = VK_NULL_HANDLE;
      VkBuffer buffer = VK_NULL_HANDLE;
      VkDeviceMemory memory = VK_NULL_HANDLE;
      uint8_t* mapped = nullptr;
      uint32_t stride = 0, slots = 0, next = 0;
      std::vector<uint32_t> free;
      int set_index = -1;
    } id_buffer;
    // The layer's own command pool, per queue family, for the read-back of presented images.
    std::map<uint32_t, VkCommandPool> pools;
    VkFence fence = VK_NULL_HANDLE;
    /// Read-back buffers not in use, by size.
    std::multimap<VkDeviceSize, std::pair<VkBuffer, VkDeviceMemory>> readback_pool;
    /// Every read-back buffer's memory, mapped once for its lifetime (not again each frame).
    std::unordered_map<VkDeviceMemory, const uint8_t*> readback_maps;
    std::shared_ptr<ReadbackLeases> leases = std::make_shared<ReadbackLeases>();
  };

  /// Makes the id buffer's set layouts, pool, set and memory (once); false when the device cannot.
  bool ensureIdBuffer(Device& d);
  /// A slot of the id buffer holding (a, b), or UINT32_MAX when all are taken.
  uint32_t takeIdSlot(Device& d, uint32_t a, uint32_t b);
  /// A host-visible buffer of the layer's (read back into), from the pool when one of the size is
  /// there; releaseReadbackBuffer() gives it back.
  bool createReadbackBuffer(Device& d, VkDeviceSize size, VkBuffer& buffer, VkDeviceMemory& memory);
  void releaseReadbackBuffer(Device& d, VkDeviceSize size, VkBuffer buffer, VkDeviceMemory memory);
  /// The bytes of a read-back buffer's memory (mapped since it was made); nullptr for none.
  static const uint8_t* readbackBytes(const Device& d, VkDeviceMemory memory);
  /// A memory type of `bits` with `flags` (UINT32_MAX if none).
  static uint32_t memoryType(const Device& d, uint32_t bits, VkMemoryPropertyFlags flags);
  /// Pointer to `size` bytes of buffer `b` at `offset`: from its shadow where it has one (nullptr
  /// unless the whole range is valid there), else from its memory, mapping it for the layer if the
  /// program has not (nullptr when not host-visible or out of range).
  const uint8_t* bufferBytes(Device& d, VkBuffer b, VkDeviceSize offset, VkDeviceSize size);
  /// Buffer `b`'s bytes from `offset` to its end (to the end of the valid range there, for a
  /// buffer with a shadow), their number in `size`; nullptr when none can be read.
  const uint8_t* bufferFrom(Device& d, VkBuffer b, VkDeviceSize offset, size_t& size);
  /// The shadow of buffer `b`, made now if it has none, when the layer follows the writes into it:
  /// its memory is not host-visible, or VIPER_VULKAN_SHADOW_COPIES is set (nullptr otherwise).
  BufferShadow* shadow(Device& d, VkBuffer b);
  /// Unmaps what bufferBytes() mapped (called before the lock is released).
  void unmapLayerMappings(Device& d);
  void freeRecording(Device& d, Recording& r);
  uint64_t& presentsSeen() { return presents_; }
  uint64_t skipFrames() const { return skip_frames_; }
  uint32_t nextSerial() { return ++serial_; }

  // The capture (frame building is in vk_frame.cpp).
  const CaptureProfile& profile() const { return profile_; }
  /// Called at each frame's end with the lock held, once the device has finished the frame (or,
  /// with `done`, once the frame's work is submitted: the writer thread waits for the fence), after
  /// its colour was read back into the read-back buffer of memory `color` (top row first, RGBA or
  /// BGRA; null when it could not be). Writes the frame: its read-back buffers (colour, the scene
  /// pass's ids and depth) are leased to the writer thread that converts them. Returns false when
  /// the frame limit says to stop.
  bool finishFrame(Device& d, VkDeviceMemory color, bool bgra, uint32_t width, uint32_t height,
                   VkFence done = VK_NULL_HANDLE);
  /// VIPER_VULKAN_DEBUG=1: what became of the draw calls the program recorded, by kind, printed
  /// with each frame (for writing a profile for a program the layer was not tried on).
  void countDraw(const char* kind) {
    if (debug_) ++draw_kinds_[kind];
  }
  /// Says once (stderr) what the layer could not do, with `what` as the key.
  void reportOnce(const std::string& what);
  void shutdown();
  /// Seconds the frames' ends spent, printed at exit when VIPER_CAPTURE_STATS is set (as the
  /// OpenGL layer prints its own): waiting for the device before the read-back (`wait_s`, added by
  /// the submission and present hooks), in finishFrame: the draw list and meshes, the read-back
  /// buffers leased to the frame's conversion, handing the frame to the writer threads; and at
  /// submission, waiting for read-back buffers a writer thread still converts (`lease_wait_s`).
  struct Stats {
    uint64_t frames = 0;
    double wait_s = 0, draws_s = 0, pixels_s = 0, push_s = 0, lease_wait_s = 0;
  };
  Stats& stats() { return stats_; }

 private:
  Layer();
  bool enabled_ = false;
  std::mutex mutex_;
  std::unordered_map<void*, std::unique_ptr<InstanceData>> instances_;
  std::unordered_map<void*, std::unique_ptr<Device>> devices_;
  uint32_t serial_ = 0;
  CaptureProfile profile_;
  /// Opens the stream at the first frame to write (false when another layer writes it, or it
  /// cannot be opened).
  bool openSink();
  std::unique_ptr<FrameSinkHandle> sink_;
  bool sink_failed_ = false;
  std::string output_;
  CaptureHeader header_;
  int zstd_level_ = 1, writer_threads_ = 1;
  std::map<std::string, bool> reported_;
  bool debug_ = false;
  /// VIPER_VULKAN_SHADOW_COPIES=1: every copy destination gets a shadow and is read from it only,
  /// so the path a discrete GPU takes runs where all memory is host-visible (lavapipe).
  bool shadow_copies_ = false;
  std::map<std::string, uint64_t> draw_kinds_;
  // Frame settings, as the OpenGL layer reads them.
  std::string condition_;
  uint64_t frame_limit_ = 0, skip_frames_ = 0, presents_ = 0, frames_written_ = 0;
  double fixed_fps_ = 0.0, start_s_ = 0.0;
  bool start_on_scene_ = false, scene_started_ = false;
  std::unordered_map<uint64_t, bool> meshes_sent_;
  std::vector<VkDeviceMemory> layer_mapped_;
  Stats stats_;

  friend class FrameBuilder;
};

/// Submission and presentation hooks (vk_frame.cpp): recordings join the frame at submit, and the
/// frame is read back and written at present.
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t count, const VkSubmitInfo* submits, VkFence fence);
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t count, const VkSubmitInfo2* submits, VkFence fence);
VKAPI_ATTR VkResult VKAPI_CALL QueuePresentKHR(VkQueue queue, const VkPresentInfoKHR* info);

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
