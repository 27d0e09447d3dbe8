// The Vulkan capture layer's view of a program: dispatch tables, the objects it follows and what a
// command buffer recorded. One lock guards it all (the layer's own state, never the program's).
// How the layer works: docs/capture_layer.md, "Vulkan".
#pragma once

#include "spirv_module.h"
#include "viper/capture/capture_frame.h"

#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace viper {
namespace capture {
namespace vulkan {

/// The dispatchable handle's loader key: every dispatchable object of one instance or device shares it.
template <typename T>
void* dispatchKey(T handle) {
  return *reinterpret_cast<void**>(handle);
}

/// A layout transition of an image's first mip level and layer (the layer's copies), no ownership
/// transfer.
inline VkImageMemoryBarrier imageBarrier(VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
                                         VkAccessFlags dst, VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) {
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  return b;
}

struct InstanceData {
  VkInstance instance = VK_NULL_HANDLE;
  PFN_vkGetInstanceProcAddr next_gipa = nullptr;
  PFN_vkDestroyInstance DestroyInstance = nullptr;
  PFN_vkGetPhysicalDeviceMemoryProperties GetPhysicalDeviceMemoryProperties = nullptr;
  PFN_vkGetPhysicalDeviceProperties GetPhysicalDeviceProperties = nullptr;
  PFN_vkGetPhysicalDeviceFeatures GetPhysicalDeviceFeatures = nullptr;
  PFN_vkGetPhysicalDeviceSurfaceCapabilitiesKHR GetPhysicalDeviceSurfaceCapabilitiesKHR = nullptr;
  PFN_vkGetPhysicalDeviceQueueFamilyProperties GetPhysicalDeviceQueueFamilyProperties = nullptr;
};

/// The next layer's (or driver's) device functions the layer calls.
struct DeviceTable {
#define VIPER_VK_DEVICE_FUNCTIONS(X)                                                                          \
  X(DestroyDevice) X(GetDeviceQueue) X(GetDeviceQueue2) X(QueueSubmit) X(QueueWaitIdle) X(DeviceWaitIdle)       \
  X(QueuePresentKHR) X(CreateSwapchainKHR) X(DestroySwapchainKHR) X(GetSwapchainImagesKHR) X(CreateImage)      \
  X(DestroyImage) X(CreateImageView) X(DestroyImageView) X(CreateBuffer) X(DestroyBuffer)                       \
  X(GetBufferMemoryRequirements) X(GetImageMemoryRequirements) X(AllocateMemory) X(FreeMemory)                  \
  X(BindBufferMemory) X(BindImageMemory) X(BindBufferMemory2) X(MapMemory) X(UnmapMemory)                       \
  X(InvalidateMappedMemoryRanges) X(CreateRenderPass) X(DestroyRenderPass) X(CreateFramebuffer)                \
  X(DestroyFramebuffer) X(CreateShaderModule) X(DestroyShaderModule) X(CreatePipelineLayout)                   \
  X(DestroyPipelineLayout) X(CreateGraphicsPipelines) X(DestroyPipeline) X(CreateDescriptorSetLayout)          \
  X(DestroyDescriptorSetLayout) X(AllocateDescriptorSets) X(UpdateDescriptorSets) X(AllocateCommandBuffers)    \
  X(FreeCommandBuffers) X(BeginCommandBuffer) X(EndCommandBuffer) X(ResetCommandBuffer) X(CmdBeginRenderPass)  \
  X(CmdEndRenderPass) X(CmdNextSubpass) X(CmdBindPipeline) X(CmdBindVertexBuffers) X(CmdBindIndexBuffer)       \
  X(CmdBindDescriptorSets) X(CmdPushConstants) X(CmdDraw) X(CmdDrawIndexed) X(CmdDrawIndirect)                 \
  X(CmdDrawIndexedIndirect) X(CmdSetViewport) X(CmdPipelineBarrier) X(CmdCopyImageToBuffer)                    \
  X(CreateCommandPool) X(DestroyCommandPool) X(ResetCommandPool) X(CreateFence) X(WaitForFences) X(ResetFences) \
  X(DestroyFence) X(CreateSemaphore) X(DestroySemaphore) X(CmdExecuteCommands) X(CmdBeginRendering)       \
  X(CreateDescriptorPool) X(DestroyDescriptorPool) X(QueueSubmit2) X(CreateRenderPass2)                    \
  X(CmdBeginRenderPass2) X(CmdNextSubpass2) X(CmdEndRenderPass2) X(CmdCopyBufferToImage)                  \
  X(CmdEndRendering) X(CmdCopyBuffer) X(CmdCopyBuffer2) X(CmdUpdateBuffer) X(CmdFillBuffer)   \
  X(CmdCopyImageToBuffer2)
#define VIPER_VK_DECLARE(name) PFN_vk##name name = nullptr;
  VIPER_VK_DEVICE_FUNCTIONS(VIPER_VK_DECLARE)
#undef VIPER_VK_DECLARE
};

struct MemoryInfo {
  VkDeviceSize size = 0;
  uint32_t type = 0;
  bool host_visible = false;
  bool coherent = false;
  void* program_mapping = nullptr;  ///< where the program mapped it (offset 0 of the mapping)
  VkDeviceSize program_offset = 0;
};

struct BufferInfo {
  VkDeviceSize size = 0;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize memory_offset = 0;
};

/// The layer's copy of a buffer it cannot read directly (memory that is not host-visible, a
/// discrete GPU's vertex, index and uniform buffers): what the program copied, updated or filled
/// into it, applied when the command buffers writing it are submitted. Only the byte ranges whose
/// contents are known are valid, and only those are read.
struct BufferShadow {
  VkDeviceSize size = 0;               ///< the buffer's
  std::unique_ptr<uint8_t[]> bytes;    ///< `size` bytes, allocated at the first write
  std::map<VkDeviceSize, VkDeviceSize> valid;  ///< disjoint [begin, end) ranges, touching ones merged

  uint8_t* data() {
    if (!bytes) bytes.reset(new uint8_t[size]);  // not zeroed: only valid ranges are read
    return bytes.get();
  }
  /// Marks [begin, end) known (`known`) or unknown.
  void mark(VkDeviceSize begin, VkDeviceSize end, bool known);
  bool covers(VkDeviceSize begin, VkDeviceSize end) const;
  /// How many bytes from `begin` on are valid, up to the first unknown one.
  VkDeviceSize validFrom(VkDeviceSize begin) const;
  /// The valid ranges within [begin, end), clipped to it.
  std::vector<std::pair<VkDeviceSize, VkDeviceSize>> validRuns(VkDeviceSize begin, VkDeviceSize end) const;
};

inline void BufferShadow::mark(VkDeviceSize begin, VkDeviceSize end, bool known) {
  if (begin >= end) return;
  VkDeviceSize lo = begin, hi = end;
  auto it = valid.upper_bound(begin);
  if (it != valid.begin() && std::prev(it)->second >= begin) --it;
  // Every range that overlaps or touches [begin, end): merged into it, or cut back to outside it.
  while (it != valid.end() && it->first <= end) {
    const VkDeviceSize b = it->first, e = it->second;
    it = valid.erase(it);
    if (known) {
      lo = std::min(lo, b), hi = std::max(hi, e);
      continue;
    }
    if (b < begin) valid.emplace(b, begin);
    if (e > end) valid.emplace(end, e);
  }
  if (known) valid.emplace(lo, hi);
}

inline VkDeviceSize BufferShadow::validFrom(VkDeviceSize begin) const {
  auto it = valid.upper_bound(begin);
  if (it == valid.begin()) return 0;
  --it;
  return it->second > begin ? it->second - begin : 0;
}

inline bool BufferShadow::covers(VkDeviceSize begin, VkDeviceSize end) const {
  return begin >= end || validFrom(begin) >= end - begin;
}

inline std::vector<std::pair<VkDeviceSize, VkDeviceSize>> BufferShadow::validRuns(VkDeviceSize begin, VkDeviceSize end) const {
  std::vector<std::pair<VkDeviceSize, VkDeviceSize>> runs;
  auto it = valid.upper_bound(begin);
  if (it != valid.begin()) --it;
  for (; it != valid.end() && it->first < end; ++it)
    if (it->second > begin) runs.emplace_back(std::max(it->first, begin), std::min(it->second, end));
  return runs;
}

/// What the layer did to a render pass: its id attachment, and the location of the id output in
/// each subpass (-1: that subpass gets no ids).
struct RenderPassInfo {
  uint32_t id_attachment = VK_ATTACHMENT_UNUSED;
  uint32_t attachment_count = 0;  ///< the program's own
  std::vector<int> id_location;   ///< per subpass
  std::vector<int> depth_attachment;  ///< per subpass, -1 none
  std::vector<int> color_attachment;  ///< per subpass: its first colour attachment, -1 none
  std::vector<VkFormat> formats;  ///< per attachment (the program's)
  std::vector<VkImageLayout> final_layouts;
  std::string why_no_ids;  ///< empty when ids are written
};

/// A single-sampled depth image the program made: read back at the end of the scene's pass.
struct DepthImage {
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t width = 0, height = 0;
};

/// The layer's id image for one size (dynamic rendering) or one framebuffer.
struct IdImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
};

struct FramebufferInfo {
  VkRenderPass render_pass = VK_NULL_HANDLE;
  uint32_t width = 0, height = 0;
  std::vector<VkImageView> views;  ///< the program's attachments (none when imageless)
  bool imageless = false;          ///< views given at each vkCmdBeginRenderPass
  IdImage ids;
  /// Imageless: how it was made (the program's image descriptions and the id attachment's), and the
  /// layer's copies of it whose descriptions name the usage the layer gave the images (the usage
  /// of the views begun with must equal the description's), by those usages.
  VkFramebufferCreateInfo create{};
  std::vector<VkFramebufferAttachmentImageInfo> image_infos;
  std::vector<std::vector<VkFormat>> view_formats;
  std::map<std::vector<VkImageUsageFlags>, VkFramebuffer> shadows;
};

struct ImageViewInfo {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
};

struct LayoutInfo {
  uint32_t layer_offset = 0;        ///< where the layer's two id words go in push constants
  VkShaderStageFlags layer_stages = 0;  ///< stage flags of the range holding them (0: not there)
  /// When the push constants leave no room: the set index of the layer's uniform buffer (-1: none;
  /// with neither, the layout's pipelines write no ids).
  int id_set = -1;
  std::vector<VkDescriptorSetLayout> set_layouts;
};

struct DescriptorSetLayoutInfo {
  struct Binding {
    VkDescriptorType type;
    uint32_t count;
  };
  std::map<uint32_t, Binding> bindings;
  uint32_t dynamicCount() const;
};

struct DescriptorBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  VkDeviceSize range = 0;
  bool dynamic = false;
};

struct DescriptorSetInfo {
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  std::map<uint32_t, DescriptorBuffer> buffers;  ///< binding (element 0) -> buffer
  std::map<uint32_t, VkImageView> images;        ///< binding (element 0) -> sampled image's view
};

/// Where one of a draw's matrices is read from.
struct MatrixSource {
  bool known = false;
  BlockMember member;
};

struct PipelineInfo {
  VkPipelineLayout layout = VK_NULL_HANDLE;
  uint64_t program_key = 0;
  bool depth_test = false;
  bool depth_only = false;  ///< no fragment shader or no colour written: a depth pre-pass
  bool ids = false;
  std::string why_no_ids;
  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  bool overlay = false;  ///< the profile says so
  bool reads_base_instance = false;  ///< its vertex shader reads gl_BaseInstance
  /// (set, binding) of the fragment shader's images, in order (spirv_module.h).
  std::vector<std::pair<uint32_t, uint32_t>> images;
  /// A viewport the pipeline sets itself (not dynamic): -1 none, else whether its height is positive.
  int static_y_down = -1;
  /// The profile says its vertex shader deforms vertices: the layer does not record deformed
  /// positions yet, so its draws have no mesh (kGapNoMesh) rather than a rigid one that is wrong.
  bool deforming = false;
  // Position attribute.
  bool has_position = false;
  uint32_t position_binding = 0;
  VkFormat position_format = VK_FORMAT_UNDEFINED;
  uint32_t position_offset = 0;
  std::map<uint32_t, uint32_t> strides;  ///< binding -> stride
  MatrixSource world, view, projection;
  /// Per-instance world (T * R * S) from members of arrays indexed by the instance (the profile's
  /// instance_translation, instance_rotation, instance_scale).
  MatrixSource instance_parts[3];
  bool instance_rotation_conjugate = false;
  uint8_t expected_matrices = 0;
  std::vector<VkShaderModule> layer_modules;  ///< rewritten modules the layer made for it
};

struct SwapchainInfo {
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{};
  std::vector<VkImage> images;
  bool readable = false;  ///< TRANSFER_SRC was added
};

/// A mat4 block member `m` at `at` (its matrix stride and majorness as the shader declares them).
inline GlMatrix readMatrix(const uint8_t* at, const BlockMember& m) {
  GlMatrix out;
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      const size_t major = m.row_major ? row : c, minor = m.row_major ? c : row;
      std::memcpy(&out(row, c), at + major * m.matrix_stride + minor * 4, 4);
    }
  return out;
}

/// One draw as a command buffer recorded it.
struct RecordedDraw {
  uint32_t local = 0;  ///< index within its recording (the id it writes)
  VkPipeline pipeline = VK_NULL_HANDLE;
  int pass = -1;  ///< render pass instance within the recording
  bool ids = false;
  bool indexed = false;
  uint32_t count = 0, instances = 1, first = 0, first_instance = 0;
  int32_t vertex_offset = 0;
  VkBuffer vertex_buffer = VK_NULL_HANDLE;
  VkDeviceSize vertex_buffer_offset = 0;
  VkBuffer index_buffer = VK_NULL_HANDLE;
  VkDeviceSize index_buffer_offset = 0;
  VkIndexType index_type = VK_INDEX_TYPE_UINT32;
  bool y_down = true;  ///< viewport height positive: Vulkan's y-down clip space
  /// Matrices read at record time (push constants) and where to read the rest at submit.
  std::array<GlMatrix, 3> matrices{GlMatrix::Identity(), GlMatrix::Identity(), GlMatrix::Identity()};
  uint8_t matrix_flags = 0;  ///< known so far
  /// What is read from buffers when the draw is submitted: world, view, projection (0-2) or an
  /// instance's translation, rotation, scale (3-5), at `offset` of `buffer`.
  struct PendingRead {
    int what = 0;
    DescriptorBuffer buffer;
    uint32_t offset = 0;
    BlockMember member;
  };
  std::vector<PendingRead> pending;
  bool rotation_conjugate = false;
  /// The images its fragment shader samples, in its order (their content keys are the draw's
  /// texture keys).
  std::vector<VkImage> textures;
};

/// A render pass instance with recorded draws: where its depth and ids are copied at its end.
struct PassCapture {
  uint32_t width = 0, height = 0;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  VkBuffer depth_buffer = VK_NULL_HANDLE, id_buffer = VK_NULL_HANDLE;
  VkDeviceMemory depth_memory = VK_NULL_HANDLE, id_memory = VK_NULL_HANDLE;
  /// The pass's colour (its first colour attachment), copied only on a device without a swapchain:
  /// there the frame's colour is the scene pass's, not a presented image's.
  VkFormat color_format = VK_FORMAT_UNDEFINED;
  VkBuffer color_buffer = VK_NULL_HANDLE;
  VkDeviceMemory color_memory = VK_NULL_HANDLE;
  uint32_t id_draws = 0;
};

/// Read-back memories whose bytes a writer thread still converts (RawImages::prepare): until they
/// are released, no submission that copies into them goes to the driver, and the pool neither hands
/// them out nor frees them. Shared with the frames' conversions (which may outlive a device).
struct ReadbackLeases {
  std::mutex mutex;
  std::condition_variable released;
  std::unordered_multiset<VkDeviceMemory> held;
  /// Fences a frame's conversion waited for, to be reset and used again (the layer's own).
  std::vector<VkFence> free_fences;

  void take(VkDeviceMemory m) {
    if (!m) return;
    std::lock_guard<std::mutex> lock(mutex);
    held.insert(m);
  }
  void give(VkDeviceMemory m) {
    if (!m) return;
    std::lock_guard<std::mutex> lock(mutex);
    auto at = held.find(m);
    if (at != held.end()) held.erase(at);
    released.notify_all();
  }
  bool isHeld(VkDeviceMemory m) {
    std::lock_guard<std::mutex> lock(mutex);
    return held.count(m) != 0;
  }
  /// Waits until `m` is released (every memory when `m` is null).
  void waitFor(VkDeviceMemory m) {
    std::unique_lock<std::mutex> lock(mutex);
    released.wait(lock, [&] { return m ? held.count(m) == 0 : held.empty(); });
  }
};

/// What a command buffer recorded since it was begun.
struct Recording {
  uint32_t serial = 0;
  std::vector<RecordedDraw> draws;
  std::vector<PassCapture> passes;
  std::vector<VkCommandBuffer> executed;  ///< secondary command buffers it executes
  // Recording state.
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  uint32_t subpass = 0;
  std::vector<VkImageView> pass_views;  ///< an imageless framebuffer's attachments, this pass
  /// Inside vkCmdBeginRendering with the layer's id attachment: its images (dynamic rendering).
  bool rendering = false;
  VkImage rendering_ids = VK_NULL_HANDLE;
  VkImage rendering_depth = VK_NULL_HANDLE;
  VkImageLayout rendering_depth_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkFormat rendering_depth_format = VK_FORMAT_UNDEFINED;
  uint32_t rendering_width = 0, rendering_height = 0;
  VkImage rendering_color = VK_NULL_HANDLE;  ///< the rendering's first colour attachment's image
  VkImageLayout rendering_color_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkFormat rendering_color_format = VK_FORMAT_UNDEFINED;
  int pass = -1;
  std::map<uint32_t, std::pair<VkBuffer, VkDeviceSize>> vertex_buffers;
  VkBuffer index_buffer = VK_NULL_HANDLE;
  VkDeviceSize index_offset = 0;
  VkIndexType index_type = VK_INDEX_TYPE_UINT32;
  std::map<uint32_t, std::pair<VkDescriptorSet, std::vector<uint32_t>>> sets;  ///< set -> (set, dynamic offsets)
  std::array<uint8_t, 256> push{};
  bool y_down = true;
  uint32_t unrecorded = 0;  ///< draws into a scene pass that could not be recorded
  std::vector<uint32_t> id_slots;  ///< slots of the layer's id buffer its draws use
  /// Uploads into images (vkCmdCopyBufferToImage), keyed when submitted: their bytes as the buffer
  /// holds them then.
  struct Upload {
    VkBuffer buffer;
    VkImage image;
    std::vector<VkBufferImageCopy> regions;
  };
  std::vector<Upload> uploads;
  /// Writes into buffers the layer keeps shadows of, in recording order, applied to the shadows
  /// when submitted: copies from `source` (vkCmdCopyBuffer, vkCmdCopyBuffer2), or, without a
  /// source, `data` repeated over `size` bytes at `offset` (vkCmdUpdateBuffer: its bytes once;
  /// vkCmdFillBuffer: its word; no data: bytes the layer does not know, copied from an image).
  struct BufferWrite {
    VkBuffer destination = VK_NULL_HANDLE;
    VkBuffer source = VK_NULL_HANDLE;
    std::vector<VkBufferCopy> regions;
    VkDeviceSize offset = 0, size = 0;
    std::vector<uint8_t> data;
  };
  std::vector<BufferWrite> buffer_writes;
};

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
