// The Vulkan layer's hooks of shader modules, pipeline layouts, descriptor sets and graphics
// pipelines: where matrices are bound, and the fragment shaders rewritten to write ids.
#include "vk_hooks.h"

#include "viper/capture/content_key.h"

#include <algorithm>

namespace viper {
namespace capture {
namespace vulkan {

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
  return recordOnSuccess(d.vk.CreatePipelineLayout(device, &copy, alloc, out), [&] { d.layouts[*out] = layout; });
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
  return recordOnSuccess(d.vk.CreateDescriptorSetLayout(device, info, alloc, out), [&] {
    DescriptorSetLayoutInfo& l = d.set_layouts[*out];
    for (uint32_t b = 0; b < info->bindingCount; ++b)
      l.bindings[info->pBindings[b].binding] = {info->pBindings[b].descriptorType, info->pBindings[b].descriptorCount};
  });
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
  return recordOnSuccess(d.vk.AllocateDescriptorSets(device, info, out), [&] {
    for (uint32_t i = 0; i < info->descriptorSetCount; ++i) d.sets[out[i]] = DescriptorSetInfo{info->pSetLayouts[i], {}};
  });
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

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
