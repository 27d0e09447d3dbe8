// The Vulkan layer's hooks of command buffers: the state it follows while the program records
// (bindings, push constants, viewports), the draws it records with their id words, and the copies
// into buffers it follows into its shadows.
#include "vk_hooks.h"

#include <algorithm>
#include <cstring>

namespace viper {
namespace capture {
namespace vulkan {

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

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
