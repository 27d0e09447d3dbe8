// The Vulkan layer's frames: recordings join the frame when they are submitted; at each present
// the presented image is copied out (a program without a swapchain: after each submission with a
// scene pass, the pass's colour), the frame's depth and ids are read from the scene pass's copies,
// every recorded draw becomes a DrawRecord (matrices in OpenGL's conventions, mesh from its
// buffers) and the frame goes to the same FrameSink the OpenGL layer writes with.
#include "capture_layer.h"

#include "../layer/capture_settings.h"
#include "../layer/frame_sink.h"
#include "../layer/mesh_extract.h"
#include "viper/capture/content_key.h"

#include <Eigen/Geometry>

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <type_traits>

namespace viper {
namespace capture {
namespace vulkan {

class FrameSinkHandle : public FrameSink {
 public:
  using FrameSink::FrameSink;
};

namespace {

using Device = Layer::Device;
using Lock = std::lock_guard<std::mutex>;

// GL clip space from Vulkan's: y down (unless the viewport flips it), depth 0..1.
// P_gl = C^-1 P_vk with C = [1 0 0 0; 0 s 0 0; 0 0 .5 .5; 0 0 0 1], s = -1 for y down.
GlMatrix glProjection(const GlMatrix& vulkan, bool y_down) {
  GlMatrix inverse = GlMatrix::Identity();
  inverse(1, 1) = y_down ? -1.0f : 1.0f;
  inverse(2, 2) = 2.0f;
  inverse(2, 3) = -1.0f;
  return inverse * vulkan;
}

float depthValue(const uint8_t* at, VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D16_UNORM_S8_UINT: {
      uint16_t v;
      std::memcpy(&v, at, 2);
      return v / 65535.0f;
    }
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT: {
      uint32_t v;
      std::memcpy(&v, at, 4);
      return static_cast<float>(v & 0xffffffu) / 16777215.0f;
    }
    default: {
      float v;
      std::memcpy(&v, at, 4);
      return v;
    }
  }
}

size_t depthBytes(VkFormat format) {
  return format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_D16_UNORM_S8_UINT ? 2 : 4;
}

// Read-back memories leased to a frame's conversion, given back when it has run or is dropped.
// With a fence (a frame whose end the program's thread did not wait for), the device is waited
// for by the conversion, and the fence goes back to the leases' pool with the memories.
class Lease {
 public:
  Lease(std::shared_ptr<ReadbackLeases> leases, std::vector<VkDeviceMemory> memories, const Device& d, VkFence done)
      : leases_(std::move(leases)), memories_(std::move(memories)), device_(d.device),
        wait_(d.vk.WaitForFences), done_(done) {
    for (VkDeviceMemory m : memories_) leases_->take(m);
  }
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;
  ~Lease() { giveBack(); }
  /// Waits until the device has finished the frame (at once without a fence).
  void waitForDevice() const {
    if (done_) wait_(device_, 1, &done_, VK_TRUE, UINT64_MAX);
  }
  void giveBack() {
    if (done_) {
      waitForDevice();  // a frame dropped unconverted: its copies may still be landing
      std::lock_guard<std::mutex> lock(leases_->mutex);
      leases_->free_fences.push_back(done_);
      done_ = VK_NULL_HANDLE;
    }
    for (VkDeviceMemory m : memories_) leases_->give(m);
    memories_.clear();
  }

 private:
  std::shared_ptr<ReadbackLeases> leases_;
  std::vector<VkDeviceMemory> memories_;
  VkDevice device_;
  PFN_vkWaitForFences wait_;
  VkFence done_;
};

// What a writer thread converts of a frame (RawImages::prepare): the read-back buffers as the
// device left them, top row first (mapped; leased until converted).
struct StagedPixels {
  uint32_t width = 0, height = 0;
  const uint8_t* color = nullptr;  ///< RGBA or BGRA (`bgra`)
  const uint8_t* ids = nullptr;    ///< (recording serial, draw in the recording, primitive, written)
  const uint8_t* depth = nullptr;  ///< in `depth_format`
  bool bgra = false;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  /// Per recording (serial), its draws' frame indices + 1 by their index in the recording (0: none).
  std::unordered_map<uint32_t, std::vector<uint32_t>> frame_index;
  std::shared_ptr<Lease> lease;
};

// Colour to RGBA, ids to (frame draw + 1, primitive), depth to floats, each bottom row first as
// RawImages holds them; then the read-back buffers are given back.
void convertStaged(const StagedPixels& s, RawImages& raw) {
  if (s.lease) s.lease->waitForDevice();
  const size_t width = s.width, height = s.height, pixels = width * height;
  if (s.color) {
    raw.rgba.resize(pixels * 4);
    for (size_t y = 0; y < height; ++y) {
      uint8_t* out = raw.rgba.data() + (height - 1 - y) * width * 4;
      std::memcpy(out, s.color + y * width * 4, width * 4);
      if (s.bgra)
        for (size_t x = 0; x < 4 * width; x += 4) std::swap(out[x], out[x + 2]);
    }
  }
  if (s.ids) {
    raw.ids.resize(pixels * 2);
    uint32_t last_serial = 0;
    const std::vector<uint32_t>* last_table = nullptr;
    for (size_t y = 0; y < height; ++y) {
      const uint32_t* row = reinterpret_cast<const uint32_t*>(s.ids) + y * width * 4;
      float* out = raw.ids.data() + (height - 1 - y) * width * 2;
      for (size_t x = 0; x < width; ++x) {
        const uint32_t* px = row + x * 4;
        // Neighbouring pixels mostly share a recording: its table is looked up again only when
        // the serial changes.
        if (px[0] != last_serial) {
          auto found = s.frame_index.find(px[0]);
          last_table = found == s.frame_index.end() ? nullptr : &found->second;
          last_serial = px[0];
        }
        const uint32_t index =
            px[3] && last_table && px[1] >= 1 && px[1] <= last_table->size() ? (*last_table)[px[1] - 1] : 0;
        out[2 * x] = static_cast<float>(index);
        out[2 * x + 1] = index ? static_cast<float>(px[2]) : 0.0f;
      }
    }
  }
  if (s.depth) {
    const size_t bytes = depthBytes(s.depth_format);
    raw.depth.resize(pixels);
    for (size_t y = 0; y < height; ++y) {
      const uint8_t* in = s.depth + y * width * bytes;
      float* out = raw.depth.data() + (height - 1 - y) * width;
      if (s.depth_format == VK_FORMAT_D32_SFLOAT || s.depth_format == VK_FORMAT_D32_SFLOAT_S8_UINT) {
        std::memcpy(out, in, width * 4);
        continue;
      }
      for (size_t x = 0; x < width; ++x) out[x] = depthValue(in + x * bytes, s.depth_format);
    }
  }
  if (s.lease) s.lease->giveBack();
}

// Matrices and instance data that live in buffers, read when their draw is submitted (what the
// GPU will read).
void readSubmittedMatrices(Device& d, Recording& r) {
  for (RecordedDraw& draw : r.draws) {
    Eigen::Vector4f parts[3];
    bool have[3] = {false, false, false};
    for (const RecordedDraw::PendingRead& p : draw.pending) {
      const BlockMember& m = p.member;
      const uint32_t bytes = p.what < 3 ? m.matrix_stride * 4 : 4 * m.components;
      const uint8_t* at = Layer::get().bufferBytes(d, p.buffer.buffer, p.buffer.offset + p.offset, bytes);
      if (!at) continue;
      if (p.what < 3) {
        draw.matrices[static_cast<size_t>(p.what)] = readMatrix(at, m);
        draw.matrix_flags |= static_cast<uint8_t>(1u << p.what);
      } else {
        Eigen::Vector4f v(0.0f, 0.0f, 0.0f, 1.0f);
        std::memcpy(v.data(), at, 4 * std::min<uint32_t>(m.components, 4));
        parts[p.what - 3] = v;
        have[p.what - 3] = true;
      }
    }
    if (!(have[0] || have[1] || have[2])) continue;
    // T * R * S, as the OpenGL layer composes an instance's attributes (its readInstanceWorld).
    Eigen::Affine3f world = Eigen::Affine3f::Identity();
    if (have[0]) world.translate(parts[0].head<3>());
    if (have[1]) {
      Eigen::Quaternionf q(parts[1][3], parts[1][0], parts[1][1], parts[1][2]);
      if (q.norm() < 1e-6f) continue;
      q.normalize();
      world.rotate(draw.rotation_conjugate ? q.conjugate() : q);
    }
    if (have[2]) world.scale(parts[2].head<3>());
    draw.matrices[0] = world.matrix();
    draw.matrix_flags |= kHasWorld;
  }
}

// The frame's scene pass, whose depth and ids (and colour, without a swapchain) the frame takes:
// of the passes in its command buffers, the one with the most recorded draws given ids (the last
// of equals); null when none has ids.
const PassCapture* scenePass(const Device& d) {
  const PassCapture* scene = nullptr;
  for (const std::shared_ptr<Recording>& r : d.frame)
    for (const PassCapture& p : r->passes)
      if (p.id_buffer && (!scene || p.id_draws >= scene->id_draws)) scene = &p;
  return scene;
}

// After the frame the frame limit asked for: the stream is closed and the program stopped.
void exitWhenDone(bool go_on) {
  if (go_on) return;
  std::fprintf(stderr, "[viper capture] captured the frames asked for, stopping the program\n");
  Layer::get().shutdown();
  std::fflush(nullptr);
  std::_Exit(0);
}

}  // namespace

uint32_t DescriptorSetLayoutInfo::dynamicCount() const {
  uint32_t n = 0;
  for (const auto& [binding, b] : bindings)
    if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC || b.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC)
      n += b.count;
  return n;
}

Layer& Layer::get() {
  static Layer* layer = new Layer;  // never destroyed: the program may still call Vulkan at exit
  return *layer;
}

namespace {
__attribute__((destructor)) void closeAtExit() { Layer::get().shutdown(); }
}  // namespace

Layer::Layer() {
  CaptureSettings settings;
  try {
    settings = readCaptureSettings();
    if (settings.output.empty()) return;  // loaded without a destination: pass-through
    if (settings.profile_path.empty()) profile_.source = "<default>";
    else profile_ = loadCaptureProfile(settings.profile_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[viper capture] Vulkan capture disabled: %s\n", e.what());
    return;
  }
  settings.header.profile = profile_.source;
  condition_ = settings.condition;
  frame_limit_ = settings.frame_limit;
  fixed_fps_ = settings.fixed_fps;
  skip_frames_ = settings.skip_frames;
  start_on_scene_ = settings.start_on_scene;
  header_ = settings.header;
  zstd_level_ = settings.zstd_level;
  writer_threads_ = settings.writer_threads;
  output_ = settings.output;
  start_s_ = monotonicSeconds();
  debug_ = std::getenv("VIPER_VULKAN_DEBUG") != nullptr;
  const char* shadow_copies = std::getenv("VIPER_VULKAN_SHADOW_COPIES");
  shadow_copies_ = shadow_copies && *shadow_copies && std::strcmp(shadow_copies, "0") != 0;
  enabled_ = true;
}

bool Layer::openSink() {
  if (sink_) return true;
  if (sink_failed_) return false;
  // One layer writes the stream: the OpenGL layer claims it when it opens it, and so does this one
  // (a program may load both APIs, e.g. to probe for Vulkan before rendering with OpenGL).
  const char* claimed = std::getenv("VIPER_CAPTURE_CLAIMED_BY");
  if (claimed && std::string(claimed) != "vulkan") {
    reportOnce(std::string("the capture is written by the ") + claimed + " layer: Vulkan frames are not recorded");
    sink_failed_ = true;
    return false;
  }
  try {
    sink_.reset(new FrameSinkHandle(output_, header_, zstd_level_, writer_threads_));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[viper capture] Vulkan capture disabled: %s\n", e.what());
    sink_failed_ = true;
    return false;
  }
  setenv("VIPER_CAPTURE_CLAIMED_BY", "vulkan", 1);
  std::fprintf(stderr, "[viper capture] capturing Vulkan frames to %s\n", output_.c_str());
  return true;
}

void Layer::shutdown() {
  Lock lock(mutex_);
  if (!sink_) return;
  sink_->close();
  if (stats_.frames && std::getenv("VIPER_CAPTURE_STATS")) {
    const double n = static_cast<double>(stats_.frames) / 1e3;
    std::fprintf(stderr,
                 "[viper capture] Vulkan: %llu frames; per frame: waiting for the device %.2f ms, draw list and meshes "
                 "%.2f ms, handing the read-back buffers over %.2f ms, waiting for the writer %.2f ms, for read-back "
                 "buffers still being converted %.2f ms; writer threads %.2f ms (%d threads, summed)\n",
                 static_cast<unsigned long long>(stats_.frames), stats_.wait_s / n, stats_.draws_s / n,
                 stats_.pixels_s / n, stats_.push_s / n, stats_.lease_wait_s / n, sink_->busySeconds() / n,
                 sink_->threads());
  }
}

void Layer::reportOnce(const std::string& what) {
  if (reported_[what]) return;
  reported_[what] = true;
  std::fprintf(stderr, "[viper capture] Vulkan: %s\n", what.c_str());
}

InstanceData* Layer::instance(void* key) {
  Lock lock(mutex_);
  auto i = instances_.find(key);
  return i == instances_.end() ? nullptr : i->second.get();
}

void Layer::addInstance(VkInstance instance, PFN_vkGetInstanceProcAddr gipa) {
  auto d = std::make_unique<InstanceData>();
  d->instance = instance;
  d->next_gipa = gipa;
#define VIPER_VK_INSTANCE_FN(name) d->name = reinterpret_cast<PFN_vk##name>(gipa(instance, "vk" #name));
  VIPER_VK_INSTANCE_FN(DestroyInstance)
  VIPER_VK_INSTANCE_FN(GetPhysicalDeviceMemoryProperties)
  VIPER_VK_INSTANCE_FN(GetPhysicalDeviceProperties)
  VIPER_VK_INSTANCE_FN(GetPhysicalDeviceFeatures)
  VIPER_VK_INSTANCE_FN(GetPhysicalDeviceSurfaceCapabilitiesKHR)
  VIPER_VK_INSTANCE_FN(GetPhysicalDeviceQueueFamilyProperties)
#undef VIPER_VK_INSTANCE_FN
  Lock lock(mutex_);
  instances_[dispatchKey(instance)] = std::move(d);
}

void Layer::removeInstance(VkInstance instance) {
  Lock lock(mutex_);
  instances_.erase(dispatchKey(instance));
}

Layer::Device* Layer::device(void* key) {
  Lock lock(mutex_);
  auto i = devices_.find(key);
  return i == devices_.end() ? nullptr : i->second.get();
}

Layer::Device* Layer::addDevice(VkPhysicalDevice physical, VkDevice device, PFN_vkGetDeviceProcAddr gdpa,
                                PFN_vkSetDeviceLoaderData set_loader_data) {
  auto d = std::make_unique<Device>();
  d->device = device;
  d->physical = physical;
  d->instance = instance(dispatchKey(physical));
  d->next_gdpa = gdpa;
  d->set_loader_data = set_loader_data;
#define VIPER_VK_LOAD(name) d->vk.name = reinterpret_cast<PFN_vk##name>(gdpa(device, "vk" #name));
  VIPER_VK_DEVICE_FUNCTIONS(VIPER_VK_LOAD)
#undef VIPER_VK_LOAD
  if (!d->vk.CmdBeginRendering)
    d->vk.CmdBeginRendering = reinterpret_cast<PFN_vkCmdBeginRendering>(gdpa(device, "vkCmdBeginRenderingKHR"));
  auto khr = [&](auto& function, const char* name) {
    if (!function) function = reinterpret_cast<std::remove_reference_t<decltype(function)>>(gdpa(device, name));
  };
  khr(d->vk.CreateRenderPass2, "vkCreateRenderPass2KHR");
  khr(d->vk.CmdBeginRenderPass2, "vkCmdBeginRenderPass2KHR");
  khr(d->vk.CmdNextSubpass2, "vkCmdNextSubpass2KHR");
  khr(d->vk.CmdEndRenderPass2, "vkCmdEndRenderPass2KHR");
  khr(d->vk.CmdCopyBuffer2, "vkCmdCopyBuffer2KHR");
  khr(d->vk.CmdCopyImageToBuffer2, "vkCmdCopyImageToBuffer2KHR");
  if (!d->vk.QueueSubmit2) d->vk.QueueSubmit2 = reinterpret_cast<PFN_vkQueueSubmit2>(gdpa(device, "vkQueueSubmit2KHR"));
  if (!d->vk.CmdEndRendering)
    d->vk.CmdEndRendering = reinterpret_cast<PFN_vkCmdEndRendering>(gdpa(device, "vkCmdEndRenderingKHR"));
  if (d->instance) {
    d->instance->GetPhysicalDeviceMemoryProperties(physical, &d->memory_properties);
    VkPhysicalDeviceProperties properties{};
    d->instance->GetPhysicalDeviceProperties(physical, &properties);
    d->limits = properties.limits;
  }
  Device* raw = d.get();
  Lock lock(mutex_);
  devices_[dispatchKey(device)] = std::move(d);
  return raw;
}

void Layer::removeDevice(VkDevice device) {
  std::unique_ptr<Device> d;
  {
    Lock lock(mutex_);
    auto i = devices_.find(dispatchKey(device));
    if (i == devices_.end()) return;
    d = std::move(i->second);
    devices_.erase(i);
  }
  d->vk.DeviceWaitIdle(device);
  d->leases->waitFor(VK_NULL_HANDLE);  // the frames' conversions are done with the read-back buffers
  for (VkFence f : d->leases->free_fences) d->vk.DestroyFence(device, f, nullptr);
  d->leases->free_fences.clear();
  for (auto& [cb, r] : d->recordings) freeRecording(*d, *r);
  for (auto& r : d->retired) freeRecording(*d, *r);
  for (auto& [family, pool] : d->pools) d->vk.DestroyCommandPool(device, pool, nullptr);
  for (auto& [size, pooled] : d->readback_pool) {
    d->vk.DestroyBuffer(device, pooled.first, nullptr);
    d->vk.FreeMemory(device, pooled.second, nullptr);
  }
  d->readback_maps.clear();
  const Device::IdBuffer& ib = d->id_buffer;
  if (ib.pool) d->vk.DestroyDescriptorPool(device, ib.pool, nullptr);
  if (ib.layout) d->vk.DestroyDescriptorSetLayout(device, ib.layout, nullptr);
  if (ib.empty) d->vk.DestroyDescriptorSetLayout(device, ib.empty, nullptr);
  if (ib.buffer) d->vk.DestroyBuffer(device, ib.buffer, nullptr);
  if (ib.memory) d->vk.FreeMemory(device, ib.memory, nullptr);
  if (d->fence) d->vk.DestroyFence(device, d->fence, nullptr);
  auto destroy = [&](const IdImage& ids) {
    if (ids.view) d->vk.DestroyImageView(device, ids.view, nullptr);
    if (ids.image) d->vk.DestroyImage(device, ids.image, nullptr);
    if (ids.memory) d->vk.FreeMemory(device, ids.memory, nullptr);
  };
  for (auto& [fb, info] : d->framebuffers) destroy(info.ids);
  for (auto& [size, ids] : d->rendering_ids) destroy(ids);
  for (auto& [p, info] : d->pipelines)
    for (VkShaderModule m : info.layer_modules) d->vk.DestroyShaderModule(device, m, nullptr);
  d->shadows.clear();
  // The Device itself is kept: hooks of other threads may still hold a reference to it.
  d.release();
}

uint32_t Layer::memoryType(const Device& d, uint32_t bits, VkMemoryPropertyFlags flags) {
  for (uint32_t t = 0; t < d.memory_properties.memoryTypeCount; ++t)
    if ((bits & (1u << t)) && (d.memory_properties.memoryTypes[t].propertyFlags & flags) == flags) return t;
  return UINT32_MAX;
}

void Layer::releaseReadbackBuffer(Device& d, VkDeviceSize size, VkBuffer buffer, VkDeviceMemory memory) {
  if (!buffer) return;
  // Kept for the next frame's copies: fresh allocations cost more in page faults than the copies
  // themselves (a CPU driver backs device memory with new pages). A few per size at most.
  if (d.readback_pool.count(size) < 8) d.readback_pool.emplace(size, std::make_pair(buffer, memory));
  else {
    d.leases->waitFor(memory);
    d.vk.DestroyBuffer(d.device, buffer, nullptr);
    d.vk.FreeMemory(d.device, memory, nullptr);
    d.readback_maps.erase(memory);
  }
}

const uint8_t* Layer::readbackBytes(const Device& d, VkDeviceMemory memory) {
  auto m = memory ? d.readback_maps.find(memory) : d.readback_maps.end();
  return m == d.readback_maps.end() ? nullptr : m->second;
}

bool Layer::createReadbackBuffer(Device& d, VkDeviceSize size, VkBuffer& buffer, VkDeviceMemory& memory) {
  auto pooled = d.readback_pool.lower_bound(size);
  while (pooled != d.readback_pool.end() && pooled->first == size && d.leases->isHeld(pooled->second.second)) ++pooled;
  if (pooled != d.readback_pool.end() && pooled->first == size) {
    buffer = pooled->second.first;
    memory = pooled->second.second;
    d.readback_pool.erase(pooled);
    return true;
  }
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (d.vk.CreateBuffer(d.device, &info, nullptr, &buffer) != VK_SUCCESS) return false;
  VkMemoryRequirements req{};
  d.vk.GetBufferMemoryRequirements(d.device, buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memoryType(d, req.memoryTypeBits,
                                     VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
                                         VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  if (alloc.memoryTypeIndex == UINT32_MAX)
    alloc.memoryTypeIndex =
        memoryType(d, req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (alloc.memoryTypeIndex == UINT32_MAX || d.vk.AllocateMemory(d.device, &alloc, nullptr, &memory) != VK_SUCCESS) {
    d.vk.DestroyBuffer(d.device, buffer, nullptr);
    buffer = VK_NULL_HANDLE;
    return false;
  }
  void* mapped = nullptr;
  if (d.vk.BindBufferMemory(d.device, buffer, memory, 0) != VK_SUCCESS ||
      d.vk.MapMemory(d.device, memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) {
    d.vk.DestroyBuffer(d.device, buffer, nullptr);
    d.vk.FreeMemory(d.device, memory, nullptr);
    buffer = VK_NULL_HANDLE;
    memory = VK_NULL_HANDLE;
    return false;
  }
  d.readback_maps[memory] = static_cast<const uint8_t*>(mapped);
  return true;
}

const uint8_t* Layer::bufferBytes(Device& d, VkBuffer b, VkDeviceSize offset, VkDeviceSize size) {
  // A buffer with a shadow is read from it only: its memory is not readable, or, with
  // VIPER_VULKAN_SHADOW_COPIES, the shadow stands for it.
  auto shadow = d.shadows.find(b);
  if (shadow != d.shadows.end()) {
    BufferShadow& s = shadow->second;
    return offset <= s.size && size <= s.size - offset && s.bytes && s.covers(offset, offset + size) ? s.bytes.get() + offset
                                                                                                       : nullptr;
  }
  auto buffer = d.buffers.find(b);
  if (buffer == d.buffers.end() || offset + size > buffer->second.size) return nullptr;
  auto memory = d.memories.find(buffer->second.memory);
  if (memory == d.memories.end() || !memory->second.host_visible) return nullptr;
  MemoryInfo& m = memory->second;
  const VkDeviceSize at = buffer->second.memory_offset + offset;
  if (m.program_mapping) {
    if (at < m.program_offset) return nullptr;
    return static_cast<const uint8_t*>(m.program_mapping) + (at - m.program_offset);
  }
  // Mapped by the layer for as long as the program does not map it (MapMemory takes the lock).
  void* mapped = nullptr;
  if (d.vk.MapMemory(d.device, buffer->second.memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) return nullptr;
  m.program_mapping = mapped;  // unmapped again at the frame's end (unmapLayerMappings)
  m.program_offset = 0;
  layer_mapped_.push_back(buffer->second.memory);
  return static_cast<const uint8_t*>(mapped) + at;
}

const uint8_t* Layer::bufferFrom(Device& d, VkBuffer b, VkDeviceSize offset, size_t& size) {
  size = 0;
  auto info = d.buffers.find(b);
  if (info == d.buffers.end() || offset > info->second.size) return nullptr;
  auto shadow = d.shadows.find(b);
  const VkDeviceSize bytes = shadow == d.shadows.end() ? info->second.size - offset : shadow->second.validFrom(offset);
  const uint8_t* at = bufferBytes(d, b, offset, bytes);
  if (at) size = static_cast<size_t>(bytes);
  return at;
}

BufferShadow* Layer::shadow(Device& d, VkBuffer b) {
  auto known = d.shadows.find(b);
  if (known != d.shadows.end()) return &known->second;
  auto info = d.buffers.find(b);
  if (info == d.buffers.end()) return nullptr;
  auto memory = d.memories.find(info->second.memory);
  if (!shadow_copies_ && memory != d.memories.end() && memory->second.host_visible) return nullptr;
  BufferShadow& made = d.shadows[b];
  made.size = info->second.size;
  return &made;
}

void Layer::unmapLayerMappings(Device& d) {
  for (VkDeviceMemory memory : layer_mapped_) {
    auto m = d.memories.find(memory);
    if (m == d.memories.end()) continue;
    d.vk.UnmapMemory(d.device, memory);
    m->second.program_mapping = nullptr;
  }
  layer_mapped_.clear();
}

bool Layer::ensureIdBuffer(Device& d) {
  Device::IdBuffer& ib = d.id_buffer;
  if (ib.set) return true;
  if (ib.set_index == -2) return false;  // tried and failed
  ib.set_index = -2;
  const uint32_t max_sets = std::min<uint32_t>(d.limits.maxBoundDescriptorSets, 32);
  if (max_sets < 2) return false;
  VkDescriptorSetLayoutBinding binding{};
  binding.binding = 0;
  binding.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
  binding.descriptorCount = 1;
  binding.stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
  VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  if (d.vk.CreateDescriptorSetLayout(d.device, &li, nullptr, &ib.empty) != VK_SUCCESS) return false;
  li.bindingCount = 1;
  li.pBindings = &binding;
  if (d.vk.CreateDescriptorSetLayout(d.device, &li, nullptr, &ib.layout) != VK_SUCCESS) return false;
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1};
  VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pi.maxSets = 1;
  pi.poolSizeCount = 1;
  pi.pPoolSizes = &size;
  if (d.vk.CreateDescriptorPool(d.device, &pi, nullptr, &ib.pool) != VK_SUCCESS) return false;
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = ib.pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &ib.layout;
  if (d.vk.AllocateDescriptorSets(d.device, &ai, &ib.set) != VK_SUCCESS) return false;
  ib.stride = static_cast<uint32_t>(std::max<VkDeviceSize>(d.limits.minUniformBufferOffsetAlignment, 16));
  ib.slots = 65536;
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = static_cast<VkDeviceSize>(ib.stride) * ib.slots;
  bi.usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
  if (d.vk.CreateBuffer(d.device, &bi, nullptr, &ib.buffer) != VK_SUCCESS) return false;
  VkMemoryRequirements req{};
  d.vk.GetBufferMemoryRequirements(d.device, ib.buffer, &req);
  VkMemoryAllocateInfo mi{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mi.allocationSize = req.size;
  mi.memoryTypeIndex =
      memoryType(d, req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (mi.memoryTypeIndex == UINT32_MAX || d.vk.AllocateMemory(d.device, &mi, nullptr, &ib.memory) != VK_SUCCESS) return false;
  d.vk.BindBufferMemory(d.device, ib.buffer, ib.memory, 0);
  void* mapped = nullptr;
  if (d.vk.MapMemory(d.device, ib.memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) return false;
  ib.mapped = static_cast<uint8_t*>(mapped);
  VkDescriptorBufferInfo buffer{ib.buffer, 0, 8};
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = ib.set;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
  write.pBufferInfo = &buffer;
  d.vk.UpdateDescriptorSets(d.device, 1, &write, 0, nullptr);
  std::memset(ib.mapped, 0, 8);  // slot 0: (0, 0), the words of draws that are not recorded
  ib.next = 1;
  ib.set_index = static_cast<int>(max_sets) - 1;  // the highest: never one a program's layouts share
  return true;
}

uint32_t Layer::takeIdSlot(Device& d, uint32_t a, uint32_t b) {
  Device::IdBuffer& ib = d.id_buffer;
  uint32_t slot = UINT32_MAX;
  if (!ib.free.empty()) {
    slot = ib.free.back();
    ib.free.pop_back();
  } else if (ib.next < ib.slots) {
    slot = ib.next++;
  } else {
    return UINT32_MAX;
  }
  const uint32_t words[2] = {a, b};
  std::memcpy(ib.mapped + static_cast<size_t>(slot) * ib.stride, words, 8);
  return slot;
}

void Layer::freeRecording(Device& d, Recording& r) {
  d.id_buffer.free.insert(d.id_buffer.free.end(), r.id_slots.begin(), r.id_slots.end());
  r.id_slots.clear();
  for (PassCapture& p : r.passes) {
    const VkDeviceSize pixels = static_cast<VkDeviceSize>(p.width) * p.height;
    releaseReadbackBuffer(d, pixels * 16, p.id_buffer, p.id_memory);
    releaseReadbackBuffer(d, pixels * 4, p.depth_buffer, p.depth_memory);
    releaseReadbackBuffer(d, pixels * 4, p.color_buffer, p.color_memory);
  }
  r.passes.clear();
}

// -----------------------------------------------------------------------------------------------
// Frames.

bool Layer::finishFrame(Device& d, VkDeviceMemory color, bool bgra, uint32_t width, uint32_t height, VkFence done) {
  // A frame not written: its fence (if any) is waited for here and goes back to the pool.
  auto notWritten = [&] {
    if (done) Lease(d.leases, {}, d, done).giveBack();
    return true;
  };
  if (!openSink()) return notWritten();
  const double start_s = monotonicSeconds();
  CaptureFrame frame;
  // The buffers of a frame written before (fresh 2-8 MB vectors cost more in page faults).
  RawImages raw = sink_->recycledRaw();
  raw.width = static_cast<int>(width);
  raw.height = static_cast<int>(height);

  // Every recorded draw of the frame, in submission order; (recording, draw + 1) -> frame draw.
  // Per recording (serial), its draws' frame indices + 1 by their index in the recording (0: none).
  std::unordered_map<uint32_t, std::vector<uint32_t>> frame_index;
  const PassCapture* scene = scenePass(d);
  std::map<VkBuffer, uint64_t> buffer_keys;
  auto bufferKey = [&](VkBuffer b) -> uint64_t {
    auto k = buffer_keys.find(b);
    if (k != buffer_keys.end()) return k->second;
    auto info = d.buffers.find(b);
    const uint8_t* bytes = info == d.buffers.end() ? nullptr : bufferBytes(d, b, 0, info->second.size);
    return buffer_keys[b] = bytes ? contentKey(bytes, info->second.size) : 0;
  };
  for (const std::shared_ptr<Recording>& r : d.frame) {
    frame.unrecorded_draws += r->unrecorded;
    for (const RecordedDraw& draw : r->draws) {
      auto pipeline = d.pipelines.find(draw.pipeline);
      if (pipeline == d.pipelines.end()) {
        ++frame.unrecorded_draws;
        continue;
      }
      const PipelineInfo& pi = pipeline->second;
      DrawRecord rec;
      rec.index = static_cast<uint32_t>(frame.draws.size());
      std::vector<uint32_t>& indices = frame_index[r->serial];
      if (indices.size() <= draw.local) indices.resize(draw.local + 1, 0);
      indices[draw.local] = rec.index + 1;
      rec.program_key = pi.program_key;
      for (VkImage image : draw.textures) {
        auto key = d.image_keys.find(image);
        rec.texture_keys.push_back(key == d.image_keys.end() ? 0 : key->second);
      }
      rec.matrix_flags = draw.matrix_flags;
      rec.world = draw.matrices[0];
      rec.view = draw.matrices[1];
      rec.projection = glProjection(draw.matrices[2], draw.y_down);
      if (profile_.left_handed) {
        // The mirror image in z, in OpenGL's right-handed conventions (capture_profile.h).
        const GlMatrix f = Eigen::Vector4f(1.0f, 1.0f, -1.0f, 1.0f).asDiagonal();
        rec.world = f * rec.world * f;
        rec.view = f * rec.view * f;
        rec.projection = rec.projection * f;
      }
      if (!draw.ids) rec.gaps |= kGapNoIds;
      if ((pi.expected_matrices & ~draw.matrix_flags) != 0) rec.gaps |= kGapMatrixMissing;
      // The mesh from its buffers (read now: staged copies have landed).
      PositionLayout layout;
      layout.type = 0x1406;  // GL_FLOAT
      layout.size = pi.position_format == VK_FORMAT_R32G32_SFLOAT         ? 2
                    : pi.position_format == VK_FORMAT_R32G32B32A32_SFLOAT ? 4
                    : pi.position_format == VK_FORMAT_R32G32B32_SFLOAT    ? 3
                                                                          : 0;
      auto strides = pi.strides.find(pi.position_binding);
      layout.stride = strides == pi.strides.end() ? 0 : strides->second;
      layout.offset = pi.position_offset;
      DrawRange range;
      range.mode = pi.topology == VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST ? 4u : 0u;
      range.count = draw.count;
      range.first = draw.indexed ? 0 : draw.first;
      range.base_vertex = draw.vertex_offset;
      rec.primitive_count = range.mode == 4 ? draw.count / 3 : 0;
      size_t vertex_bytes = 0;
      const uint8_t* vertices = bufferFrom(d, draw.vertex_buffer, draw.vertex_buffer_offset, vertex_bytes);
      bool mesh_ok = vertices && layout.size > 0 && range.mode == 4 && !pi.deforming;
      if (mesh_ok && draw.indexed) {
        const size_t index_size = draw.index_type == VK_INDEX_TYPE_UINT16 ? 2 : 4;
        range.index_data = bufferFrom(d, draw.index_buffer, draw.index_buffer_offset, range.index_bytes);
        range.index_type = index_size == 2 ? 0x1403u : 0x1405u;  // GL_UNSIGNED_SHORT / INT
        range.index_offset = static_cast<size_t>(draw.first) * index_size;
        mesh_ok = range.index_data != nullptr && draw.index_type != VK_INDEX_TYPE_UINT8_EXT;
        rec.index_buffer_key = bufferKey(draw.index_buffer);
      }
      ExtractedMesh mesh;
      if (mesh_ok && extractMesh(vertices, vertex_bytes, layout, range, mesh)) {
        rec.mesh_key = mesh.mesh.key;
        rec.vertex_buffer_key = bufferKey(draw.vertex_buffer);
        if (!meshes_sent_[mesh.mesh.key]) {
          meshes_sent_[mesh.mesh.key] = true;
          if (profile_.left_handed)
            for (size_t i = 2; i < mesh.mesh.positions_xyz.size(); i += 3) mesh.mesh.positions_xyz[i] = -mesh.mesh.positions_xyz[i];
          frame.new_meshes.push_back(std::move(mesh.mesh));
        }
      } else {
        rec.gaps |= kGapNoMesh;
      }
      frame.draws.push_back(std::move(rec));
    }
  }
  if (meshes_sent_.size() > 65536) meshes_sent_.clear();  // streamed geometry: memory stays bounded
  // --start-on-scene: nothing is written before the first frame with a draw that has the camera's
  // view and projection (menus and loading screens have none).
  if (start_on_scene_ && !scene_started_) {
    scene_started_ = std::any_of(frame.draws.begin(), frame.draws.end(), [](const DrawRecord& r) {
      return (r.matrix_flags & (kHasView | kHasProjection)) == (kHasView | kHasProjection);
    });
    if (!scene_started_) {
      meshes_sent_.clear();  // the meshes go with the first frame written
      unmapLayerMappings(d);
      return notWritten();
    }
  }

  const double pixels_s = monotonicSeconds();
  stats_.draws_s += pixels_s - start_s;
  // The read-back buffers go to a writer thread as they are, leased until it has converted them
  // (convertStaged).
  StagedPixels staged;
  staged.width = width;
  staged.height = height;
  staged.color = readbackBytes(d, color);
  staged.bgra = bgra;
  if (scene && (scene->width != width || scene->height != height)) {
    reportOnce("the scene's render target is " + std::to_string(scene->width) + "x" + std::to_string(scene->height) +
               ", the window " + std::to_string(width) + "x" + std::to_string(height) + ": no depth or ids written");
    scene = nullptr;
  }
  std::vector<VkDeviceMemory> leased;
  if (staged.color) leased.push_back(color);
  if (scene) {
    staged.ids = readbackBytes(d, scene->id_memory);
    staged.depth = readbackBytes(d, scene->depth_memory);
    staged.depth_format = scene->depth_format;
    staged.frame_index = std::move(frame_index);
    if (staged.ids) leased.push_back(scene->id_memory);
    if (staged.depth) leased.push_back(scene->depth_memory);
  }
  if (!leased.empty() || done) {
    staged.lease = std::make_shared<Lease>(d.leases, std::move(leased), d, done);
    raw.prepare = [staged = std::move(staged)](RawImages& r) { convertStaged(staged, r); };
  }
  unmapLayerMappings(d);
  frame.number = frames_written_;
  frame.time_s = fixed_fps_ > 0.0 ? static_cast<double>(frame.number) / fixed_fps_ : monotonicSeconds() - start_s_;
  frame.condition = condition_;
  frame.width = width;
  frame.height = height;
  if (debug_) {
    std::string kinds;
    for (const auto& [kind, n] : draw_kinds_) kinds += " " + kind + " " + std::to_string(n) + ";";
    std::fprintf(stderr, "[viper capture] Vulkan frame %llu: %zu command buffers submitted, %zu draws recorded; draw calls recorded since the last frame:%s\n",
                 static_cast<unsigned long long>(frame.number), d.frame.size(), frame.draws.size(), kinds.c_str());
    draw_kinds_.clear();
  }
  const double push_s = monotonicSeconds();
  stats_.pixels_s += push_s - pixels_s;
  sink_->push(std::move(frame), std::move(raw));
  stats_.push_s += monotonicSeconds() - push_s;
  ++stats_.frames;
  ++frames_written_;
  return !(frame_limit_ && frames_written_ >= frame_limit_);
}

namespace {

Device& deviceOf(VkQueue queue) { return *Layer::get().device(dispatchKey(queue)); }

void endFrame(Device& d) {
  d.frame.clear();
  for (auto& r : d.retired)
    if (r.use_count() == 1) Layer::get().freeRecording(d, *r);
  d.retired.erase(std::remove_if(d.retired.begin(), d.retired.end(),
                                 [](const std::shared_ptr<Recording>& r) { return r->passes.empty(); }),
                  d.retired.end());
}

}  // namespace

namespace {

// Bytes of a texel (of a 4x4 block for block-compressed formats; `block` set) of the formats
// programs upload textures in; 0 for others (not keyed).
uint32_t texelBytes(VkFormat f, bool& block) {
  block = false;
  switch (f) {
    case VK_FORMAT_R8_UNORM: return 1;
    case VK_FORMAT_R8G8_UNORM: return 2;
    case VK_FORMAT_R8G8B8A8_UNORM: case VK_FORMAT_R8G8B8A8_SRGB: case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB: case VK_FORMAT_A2B10G10R10_UNORM_PACK32: case VK_FORMAT_R32_SFLOAT: return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT: return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    case VK_FORMAT_BC1_RGB_UNORM_BLOCK: case VK_FORMAT_BC1_RGB_SRGB_BLOCK: case VK_FORMAT_BC1_RGBA_UNORM_BLOCK:
    case VK_FORMAT_BC1_RGBA_SRGB_BLOCK: case VK_FORMAT_BC4_UNORM_BLOCK: block = true; return 8;
    case VK_FORMAT_BC2_UNORM_BLOCK: case VK_FORMAT_BC2_SRGB_BLOCK: case VK_FORMAT_BC3_UNORM_BLOCK:
    case VK_FORMAT_BC3_SRGB_BLOCK: case VK_FORMAT_BC5_UNORM_BLOCK: case VK_FORMAT_BC7_UNORM_BLOCK:
    case VK_FORMAT_BC7_SRGB_BLOCK: block = true; return 16;
    default: return 0;
  }
}

// Textures the program uploads: each image's key is the content key of the bytes its first mip
// level is copied from (what the texture is, whatever image holds it).
void keyUploads(Device& d, const Recording& r) {
  for (const Recording::Upload& u : r.uploads) {
    auto format = d.image_formats.find(u.image);
    bool block = false;
    const uint32_t texel = format == d.image_formats.end() ? 0 : texelBytes(format->second, block);
    if (!texel) continue;
    uint64_t key = 0;
    for (const VkBufferImageCopy& c : u.regions) {
      if (c.imageSubresource.mipLevel != 0) continue;
      const uint64_t row_texels = c.bufferRowLength ? c.bufferRowLength : c.imageExtent.width;
      const uint64_t rows = c.bufferImageHeight ? c.bufferImageHeight : c.imageExtent.height;
      const uint64_t layers = static_cast<uint64_t>(c.imageExtent.depth) * c.imageSubresource.layerCount;
      const uint64_t bytes =
          block ? ((row_texels + 3) / 4) * ((rows + 3) / 4) * texel * layers : row_texels * rows * texel * layers;
      const uint8_t* at = Layer::get().bufferBytes(d, u.buffer, c.bufferOffset, bytes);
      if (at) key = combineKeys(key, contentKey(at, bytes));
    }
    if (key) d.image_keys[u.image] = key;
  }
}

// One region copied into a shadow: from the source's own shadow where it has one (what is unknown
// there stays unknown), else from its memory where the layer can read it (a staging buffer, read
// now, before the program reuses it); else the region becomes unknown.
void copyIntoShadow(Device& d, VkBuffer source, const VkBufferCopy& c, BufferShadow& to) {
  if (c.dstOffset > to.size || c.size > to.size - c.dstOffset) return;  // not a valid copy: ignored
  to.mark(c.dstOffset, c.dstOffset + c.size, false);
  auto from = d.shadows.find(source);
  if (from != d.shadows.end()) {
    const BufferShadow& s = from->second;
    if (c.srcOffset > s.size || c.size > s.size - c.srcOffset) return;
    for (const auto& [begin, end] : s.validRuns(c.srcOffset, c.srcOffset + c.size)) {
      const VkDeviceSize at = c.dstOffset + (begin - c.srcOffset);
      std::memmove(to.data() + at, s.bytes.get() + begin, end - begin);
      to.mark(at, at + (end - begin), true);
    }
    return;
  }
  const uint8_t* bytes = Layer::get().bufferBytes(d, source, c.srcOffset, c.size);
  if (!bytes) {
    Layer::get().reportOnce("copies from buffers the layer cannot read (not host-visible, not copied into) are not "
                            "followed: meshes and matrices read where they land are missing");
    return;
  }
  std::memcpy(to.data() + c.dstOffset, bytes, c.size);
  to.mark(c.dstOffset, c.dstOffset + c.size, true);
}

// vkCmdUpdateBuffer's bytes, or vkCmdFillBuffer's word repeated, written into a shadow; without
// data, the range becomes unknown.
void writeIntoShadow(const Recording::BufferWrite& w, BufferShadow& to) {
  if (w.offset > to.size || w.size > to.size - w.offset) return;
  if (w.data.empty()) {
    to.mark(w.offset, w.offset + w.size, false);
    return;
  }
  uint8_t* out = to.data() + w.offset;
  for (VkDeviceSize i = 0; i < w.size; i += w.data.size())
    std::memcpy(out + i, w.data.data(), std::min<VkDeviceSize>(w.data.size(), w.size - i));
  to.mark(w.offset, w.offset + w.size, true);
}

// A submitted recording's writes into buffers, applied to their shadows in recording order.
void applyBufferWrites(Device& d, const Recording& r) {
  for (const Recording::BufferWrite& w : r.buffer_writes) {
    auto shadow = d.shadows.find(w.destination);
    if (shadow == d.shadows.end()) continue;  // the buffer was destroyed since
    if (!w.source) {
      writeIntoShadow(w, shadow->second);
      continue;
    }
    for (const VkBufferCopy& c : w.regions) copyIntoShadow(d, w.source, c, shadow->second);
  }
}

// Whether a recording drew into a pass whose ids are read back.
bool hasScenePass(const Recording& r) {
  return std::any_of(r.passes.begin(), r.passes.end(), [](const PassCapture& p) { return p.id_buffer != VK_NULL_HANDLE; });
}

// A submitted command buffer's recording joins the frame (and those of the secondaries it
// executes): its writes into buffers are applied to their shadows first, so that its draws read
// what they wrote, then its matrices are read from their buffers and the textures it uploads
// keyed. Returns whether one of them drew into a pass whose ids are read back.
bool joinFrame(Device& d, VkCommandBuffer cb) {
  auto r = d.recordings.find(cb);
  if (r == d.recordings.end()) return false;
  std::vector<std::shared_ptr<Recording>> joined{r->second};
  for (VkCommandBuffer secondary : r->second->executed) {
    auto sr = d.recordings.find(secondary);
    if (sr != d.recordings.end()) joined.push_back(sr->second);
  }
  // Its copies must not overwrite read-back buffers a frame's conversion still reads.
  const double wait_s = monotonicSeconds();
  for (const std::shared_ptr<Recording>& j : joined)
    for (const PassCapture& p : j->passes)
      for (VkDeviceMemory m : {p.id_memory, p.depth_memory, p.color_memory})
        if (m) d.leases->waitFor(m);
  Layer::get().stats().lease_wait_s += monotonicSeconds() - wait_s;
  for (const std::shared_ptr<Recording>& j : joined) applyBufferWrites(d, *j);
  keyUploads(d, *r->second);
  bool scene = false;
  for (const std::shared_ptr<Recording>& j : joined) {
    readSubmittedMatrices(d, *j);
    d.frame.push_back(j);
    scene |= hasScenePass(*j);
  }
  return scene;
}

// A fence of the layer's, unsignalled (from the pool, or made); null when none could be made.
VkFence layerFence(Device& d) {
  VkFence fence = VK_NULL_HANDLE;
  {
    std::lock_guard<std::mutex> lock(d.leases->mutex);
    if (!d.leases->free_fences.empty()) {
      fence = d.leases->free_fences.back();
      d.leases->free_fences.pop_back();
    }
  }
  if (fence) {
    if (d.vk.ResetFences(d.device, 1, &fence) == VK_SUCCESS) return fence;
    d.vk.DestroyFence(d.device, fence, nullptr);
  }
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fence = VK_NULL_HANDLE;
  return d.vk.CreateFence(d.device, &fi, nullptr, &fence) == VK_SUCCESS ? fence : VK_NULL_HANDLE;
}

// A program without a swapchain (an offscreen renderer) presents nothing: its frame ends with each
// submission that carries a scene pass, and the frame's colour is the scene pass's colour
// attachment (copied at the pass's end). On a device whose program uses one queue, a fence
// submitted after the frame's work is what the frame's conversion waits for (the program goes on
// at once); with several queues the device is waited for here.
void endSubmittedFrame(Device& d, VkQueue queue) {
  Layer& layer = Layer::get();
  std::unique_lock<std::mutex> lock(layer.mutex());
  if (layer.presentsSeen()++ < layer.skipFrames()) {
    endFrame(d);
    return;
  }
  const PassCapture* scene = scenePass(d);
  if (!scene) {
    endFrame(d);
    return;
  }
  VkFence done = d.queue_families.size() == 1 ? layerFence(d) : VK_NULL_HANDLE;
  if (done && d.vk.QueueSubmit(queue, 0, nullptr, done) != VK_SUCCESS) {
    d.vk.DestroyFence(d.device, done, nullptr);
    done = VK_NULL_HANDLE;
  }
  if (!done) {
    const double wait_s = monotonicSeconds();
    d.vk.DeviceWaitIdle(d.device);
    layer.stats().wait_s += monotonicSeconds() - wait_s;
  }
  if (!Layer::readbackBytes(d, scene->color_memory)) {
    layer.reportOnce("frames without colour: the scene pass of a program without a swapchain has no colour "
                     "attachment the layer can copy (8-bit RGBA or BGRA, made while the layer was loaded)");
  }
  const bool bgra = scene->color_format == VK_FORMAT_B8G8R8A8_UNORM || scene->color_format == VK_FORMAT_B8G8R8A8_SRGB;
  const bool go_on = layer.finishFrame(d, scene->color_memory, bgra, scene->width, scene->height, done);
  endFrame(d);
  lock.unlock();
  exitWhenDone(go_on);
}

// A submission's command buffers (`each` calls its argument with each) join the frame; on a device
// without a swapchain the frame ends after the driver took a submission with a scene pass.
template <typename EachCommandBuffer, typename Forward>
VkResult submit(Device& d, VkQueue queue, EachCommandBuffer each, Forward forward) {
  Layer& layer = Layer::get();
  bool frame_ends = false;
  if (layer.capturing()) {
    Lock lock(layer.mutex());
    each([&](VkCommandBuffer cb) { frame_ends |= joinFrame(d, cb); });
    layer.unmapLayerMappings(d);
    frame_ends &= d.swapchains.empty();
  }
  const VkResult r = forward();
  if (frame_ends && r == VK_SUCCESS) endSubmittedFrame(d, queue);
  return r;
}

}  // namespace

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t count, const VkSubmitInfo* submits, VkFence fence) {
  Device& d = deviceOf(queue);
  return submit(
      d, queue,
      [&](auto join) {
        for (uint32_t s = 0; s < count; ++s)
          for (uint32_t c = 0; c < submits[s].commandBufferCount; ++c) join(submits[s].pCommandBuffers[c]);
      },
      [&] { return d.vk.QueueSubmit(queue, count, submits, fence); });
}

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t count, const VkSubmitInfo2* submits, VkFence fence) {
  Device& d = deviceOf(queue);
  return submit(
      d, queue,
      [&](auto join) {
        for (uint32_t s = 0; s < count; ++s)
          for (uint32_t c = 0; c < submits[s].commandBufferInfoCount; ++c) join(submits[s].pCommandBufferInfos[c].commandBuffer);
      },
      [&] { return d.vk.QueueSubmit2(queue, count, submits, fence); });
}

VKAPI_ATTR VkResult VKAPI_CALL QueuePresentKHR(VkQueue queue, const VkPresentInfoKHR* info) {
  Device& d = deviceOf(queue);
  Layer& layer = Layer::get();
  if (!layer.capturing() || info->swapchainCount == 0) return d.vk.QueuePresentKHR(queue, info);
  std::unique_lock<std::mutex> lock(layer.mutex());
  const bool write = layer.presentsSeen()++ >= layer.skipFrames();
  auto sc = d.swapchains.find(info->pSwapchains[0]);
  if (!write || sc == d.swapchains.end()) {
    endFrame(d);
    lock.unlock();
    return d.vk.QueuePresentKHR(queue, info);
  }
  const SwapchainInfo& swapchain = sc->second;
  const uint32_t width = swapchain.extent.width, height = swapchain.extent.height;
  VkPresentInfoKHR copy = *info;
  VkSemaphore done = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  const uint32_t family = d.queue_families.count(queue) ? d.queue_families[queue] : 0;
  const bool bgra = swapchain.format == VK_FORMAT_B8G8R8A8_UNORM || swapchain.format == VK_FORMAT_B8G8R8A8_SRGB;
  const bool rgba_format = swapchain.format == VK_FORMAT_R8G8B8A8_UNORM || swapchain.format == VK_FORMAT_R8G8B8A8_SRGB;
  if (swapchain.readable && (bgra || rgba_format) &&
      layer.createReadbackBuffer(d, static_cast<VkDeviceSize>(width) * height * 4, buffer, memory)) {
    if (!d.pools.count(family)) {
      VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
      pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
      pi.queueFamilyIndex = family;
      d.vk.CreateCommandPool(d.device, &pi, nullptr, &d.pools[family]);
      VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
      if (!d.fence) d.vk.CreateFence(d.device, &fi, nullptr, &d.fence);
    }
    pool = d.pools[family];
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    d.vk.AllocateCommandBuffers(d.device, &ai, &cb);
    if (d.set_loader_data) d.set_loader_data(d.device, cb);
    else *reinterpret_cast<void**>(cb) = dispatchKey(d.device);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    d.vk.BeginCommandBuffer(cb, &bi);
    const VkImage image = swapchain.images[info->pImageIndices[0]];
    VkImageMemoryBarrier barrier = imageBarrier(image, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                                VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                            nullptr, 1, &barrier);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    d.vk.CmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
    barrier = imageBarrier(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                           VK_ACCESS_TRANSFER_READ_BIT, 0);
    d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0,
                            nullptr, 1, &barrier);
    d.vk.EndCommandBuffer(cb);
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    d.vk.CreateSemaphore(d.device, &si, nullptr, &done);
    std::vector<VkPipelineStageFlags> stages(info->waitSemaphoreCount, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.waitSemaphoreCount = info->waitSemaphoreCount;
    submit.pWaitSemaphores = info->pWaitSemaphores;
    submit.pWaitDstStageMask = stages.data();
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &done;
    d.vk.QueueSubmit(queue, 1, &submit, d.fence);
    const double wait_s = monotonicSeconds();
    d.vk.WaitForFences(d.device, 1, &d.fence, VK_TRUE, UINT64_MAX);
    layer.stats().wait_s += monotonicSeconds() - wait_s;
    d.vk.ResetFences(d.device, 1, &d.fence);
    copy.waitSemaphoreCount = 1;
    copy.pWaitSemaphores = &done;
  } else if (!swapchain.readable || !(bgra || rgba_format)) {
    layer.reportOnce("presented images of format " + std::to_string(swapchain.format) + " are not read back");
  }
  // Every submission of the frame is done before its copies are read (simple, and slow on a GPU:
  // the read-back is synchronous for now).
  const double idle_s = monotonicSeconds();
  d.vk.DeviceWaitIdle(d.device);
  layer.stats().wait_s += monotonicSeconds() - idle_s;
  const bool go_on = layer.finishFrame(d, memory, bgra, width, height);
  if (buffer) {
    layer.releaseReadbackBuffer(d, static_cast<VkDeviceSize>(width) * height * 4, buffer, memory);
    d.vk.FreeCommandBuffers(d.device, pool, 1, &cb);
  }
  endFrame(d);
  lock.unlock();
  const VkResult r = d.vk.QueuePresentKHR(queue, &copy);
  if (done) {
    // The semaphore is waited on by the present: destroyed once the queue is idle.
    d.vk.QueueWaitIdle(queue);
    d.vk.DestroySemaphore(d.device, done, nullptr);
  }
  exitWhenDone(go_on);
  return r;
}

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
