// The Vulkan layer's hooks of render passes, framebuffers and dynamic rendering: the id attachment
// it adds, and the copies of depth, ids (and colour) it records at the end of a pass with ids.
#include "vk_hooks.h"

#include <algorithm>
#include <tuple>

namespace viper {
namespace capture {
namespace vulkan {

// ---------------------------------------------------------------------------------------------
// Render passes and framebuffers: the id attachment.

// Render passes of Vulkan 1.0's structures and of the "2" ones (vkCreateRenderPass2), edited alike.
struct RenderPass1 {
  using Info = VkRenderPassCreateInfo;
  using Attachment = VkAttachmentDescription;
  using Subpass = VkSubpassDescription;
  using Reference = VkAttachmentReference;
  static Reference reference(uint32_t attachment, VkImageLayout layout) { return {attachment, layout}; }
  static Attachment attachment() { return Attachment{}; }
  static bool multiview(const Subpass&) { return false; }
};
struct RenderPass2 {
  using Info = VkRenderPassCreateInfo2;
  using Attachment = VkAttachmentDescription2;
  using Subpass = VkSubpassDescription2;
  using Reference = VkAttachmentReference2;
  static Reference reference(uint32_t attachment, VkImageLayout layout) {
    return {VK_STRUCTURE_TYPE_ATTACHMENT_REFERENCE_2, nullptr, attachment, layout, VK_IMAGE_ASPECT_COLOR_BIT};
  }
  static Attachment attachment() { return Attachment{VK_STRUCTURE_TYPE_ATTACHMENT_DESCRIPTION_2}; }
  static bool multiview(const Subpass& s) { return s.viewMask != 0; }
};

// The id attachment added to every single-sampled subpass with depth, the depth stored. `copy` is
// the create info to pass on (pointing into the vectors given).
template <typename P>
struct EditedRenderPass {
  RenderPassInfo rp;
  typename P::Info copy;
  std::vector<typename P::Attachment> attachments;
  std::vector<typename P::Subpass> subpasses;
  std::vector<std::vector<typename P::Reference>> colors, resolves;

  EditedRenderPass(const Device& d, const typename P::Info* info) : copy(*info) {
    rp.attachment_count = info->attachmentCount;
    for (uint32_t a = 0; a < info->attachmentCount; ++a) {
      rp.formats.push_back(info->pAttachments[a].format);
      rp.final_layouts.push_back(info->pAttachments[a].finalLayout);
    }
    rp.id_location.assign(info->subpassCount, -1);
    rp.depth_attachment.assign(info->subpassCount, -1);
    rp.color_attachment.assign(info->subpassCount, -1);
    attachments.assign(info->pAttachments, info->pAttachments + info->attachmentCount);
    subpasses.assign(info->pSubpasses, info->pSubpasses + info->subpassCount);
    colors.resize(info->subpassCount);
    resolves.resize(info->subpassCount);
    bool any = false;
    for (uint32_t s = 0; s < info->subpassCount && L().capturing() && d.primitive_id; ++s) {
      const typename P::Subpass& sp = info->pSubpasses[s];
      if (!sp.pDepthStencilAttachment || sp.pDepthStencilAttachment->attachment == VK_ATTACHMENT_UNUSED) continue;
      const uint32_t depth = sp.pDepthStencilAttachment->attachment;
      rp.depth_attachment[s] = static_cast<int>(depth);
      if (sp.colorAttachmentCount > 0 && sp.pColorAttachments[0].attachment != VK_ATTACHMENT_UNUSED)
        rp.color_attachment[s] = static_cast<int>(sp.pColorAttachments[0].attachment);
      if (attachments[depth].samples != VK_SAMPLE_COUNT_1_BIT || P::multiview(sp)) {
        rp.why_no_ids = P::multiview(sp) ? "multiview subpass" : "multisampled depth attachment";
        continue;
      }
      attachments[depth].storeOp = VK_ATTACHMENT_STORE_OP_STORE;  // read back at the pass's end
      colors[s].assign(sp.pColorAttachments, sp.pColorAttachments + sp.colorAttachmentCount);
      rp.id_location[s] = static_cast<int>(sp.colorAttachmentCount);
      colors[s].push_back(P::reference(info->attachmentCount, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL));
      subpasses[s].colorAttachmentCount = static_cast<uint32_t>(colors[s].size());
      subpasses[s].pColorAttachments = colors[s].data();
      if (sp.pResolveAttachments) {
        resolves[s].assign(sp.pResolveAttachments, sp.pResolveAttachments + sp.colorAttachmentCount);
        resolves[s].push_back(P::reference(VK_ATTACHMENT_UNUSED, VK_IMAGE_LAYOUT_UNDEFINED));
        subpasses[s].pResolveAttachments = resolves[s].data();
      }
      any = true;
    }
    if (any) {
      rp.id_attachment = info->attachmentCount;
      typename P::Attachment id = P::attachment();
      id.format = kIdFormat;
      id.samples = VK_SAMPLE_COUNT_1_BIT;
      id.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      id.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      id.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
      id.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
      id.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      id.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      attachments.push_back(id);
      copy.attachmentCount = static_cast<uint32_t>(attachments.size());
      copy.pAttachments = attachments.data();
      copy.pSubpasses = subpasses.data();
    } else if (rp.why_no_ids.empty()) {
      rp.why_no_ids = !L().capturing() || d.primitive_id ? "no depth attachment"
                                                         : "the device lacks geometryShader or independentBlend";
    }
  }
};

template <typename P, typename Create>
VkResult createRenderPassEdited(VkDevice device, const typename P::Info* info, const VkAllocationCallbacks* alloc,
                                VkRenderPass* out, Create create) {
  Device& d = dev(device);
  EditedRenderPass<P> edited(d, info);
  return recordOnSuccess(create(device, &edited.copy, alloc, out),
                         [&] { d.render_passes[*out] = std::move(edited.rp); });
}

VKAPI_ATTR VkResult VKAPI_CALL CreateRenderPass(VkDevice device, const VkRenderPassCreateInfo* info,
                                                const VkAllocationCallbacks* alloc, VkRenderPass* out) {
  return createRenderPassEdited<RenderPass1>(device, info, alloc, out, dev(device).vk.CreateRenderPass);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateRenderPass2(VkDevice device, const VkRenderPassCreateInfo2* info,
                                                 const VkAllocationCallbacks* alloc, VkRenderPass* out) {
  return createRenderPassEdited<RenderPass2>(device, info, alloc, out, dev(device).vk.CreateRenderPass2);
}

VKAPI_ATTR void VKAPI_CALL DestroyRenderPass(VkDevice device, VkRenderPass pass, const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  forget(pass, d.render_passes);
  d.vk.DestroyRenderPass(device, pass, alloc);
}

// The layer's id image (RGBA32UI: recording, draw, primitive, written) of one size.
IdImage makeIdImage(Device& d, uint32_t width, uint32_t height, uint32_t layers) {
  IdImage ids;
  VkImageCreateInfo image{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  image.imageType = VK_IMAGE_TYPE_2D;
  image.format = kIdFormat;
  image.extent = {width, height, 1};
  image.mipLevels = 1;
  image.arrayLayers = layers;
  image.samples = VK_SAMPLE_COUNT_1_BIT;
  image.tiling = VK_IMAGE_TILING_OPTIMAL;
  image.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  image.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  if (d.vk.CreateImage(d.device, &image, nullptr, &ids.image) != VK_SUCCESS) return IdImage{};
  VkMemoryRequirements req{};
  d.vk.GetImageMemoryRequirements(d.device, ids.image, &req);
  VkMemoryAllocateInfo mem{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mem.allocationSize = req.size;
  mem.memoryTypeIndex = Layer::memoryType(d, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (mem.memoryTypeIndex == UINT32_MAX) mem.memoryTypeIndex = Layer::memoryType(d, req.memoryTypeBits, 0);
  d.vk.AllocateMemory(d.device, &mem, nullptr, &ids.memory);
  d.vk.BindImageMemory(d.device, ids.image, ids.memory, 0);
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = ids.image;
  view.viewType = layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
  view.format = kIdFormat;
  view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
  d.vk.CreateImageView(d.device, &view, nullptr, &ids.view);
  return ids;
}

void destroyIdImage(Device& d, const IdImage& ids) {
  if (ids.view) d.vk.DestroyImageView(d.device, ids.view, nullptr);
  if (ids.image) d.vk.DestroyImage(d.device, ids.image, nullptr);
  if (ids.memory) d.vk.FreeMemory(d.device, ids.memory, nullptr);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateFramebuffer(VkDevice device, const VkFramebufferCreateInfo* info,
                                                 const VkAllocationCallbacks* alloc, VkFramebuffer* out) {
  Device& d = dev(device);
  FramebufferInfo fb;
  fb.render_pass = info->renderPass;
  fb.width = info->width, fb.height = info->height;
  bool ids = false;
  {
    Lock lock(L().mutex());
    auto rp = d.render_passes.find(info->renderPass);
    ids = rp != d.render_passes.end() && rp->second.id_attachment != VK_ATTACHMENT_UNUSED;
  }
  VkFramebufferCreateInfo copy = *info;
  if (info->flags & VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT) {
    // Imageless: the id attachment's description joins the program's; its view is given at each
    // vkCmdBeginRenderPass (BeginEdit).
    fb.imageless = true;
    auto* described = const_cast<VkFramebufferAttachmentsCreateInfo*>(findInChain<VkFramebufferAttachmentsCreateInfo>(
        info->pNext, VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO));
    if (!L().capturing() || !described) return d.vk.CreateFramebuffer(device, info, alloc, out);
    const VkFramebufferAttachmentsCreateInfo original = *described;
    std::vector<VkFramebufferAttachmentImageInfo> images(described->pAttachmentImageInfos,
                                                         described->pAttachmentImageInfos + described->attachmentImageInfoCount);
    static const VkFormat id_format = kIdFormat;
    if (ids) {
      VkFramebufferAttachmentImageInfo id{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENT_IMAGE_INFO};
      id.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      id.width = info->width, id.height = info->height, id.layerCount = std::max(1u, info->layers);
      id.viewFormatCount = 1;
      id.pViewFormats = &id_format;
      images.push_back(id);
      described->attachmentImageInfoCount = static_cast<uint32_t>(images.size());
      described->pAttachmentImageInfos = images.data();
      copy.attachmentCount = described->attachmentImageInfoCount;
      fb.ids = makeIdImage(d, info->width, info->height, std::max(1u, info->layers));
    }
    const VkResult r = d.vk.CreateFramebuffer(device, &copy, alloc, out);
    fb.create = *info;
    fb.create.pNext = nullptr;
    fb.create.attachmentCount = copy.attachmentCount;
    fb.image_infos = images;
    for (VkFramebufferAttachmentImageInfo& image : fb.image_infos) {
      fb.view_formats.emplace_back(image.pViewFormats, image.pViewFormats + image.viewFormatCount);
      image.pNext = nullptr;
    }
    *described = original;
    Lock lock(L().mutex());
    if (r == VK_SUCCESS) d.framebuffers[*out] = fb;
    else destroyIdImage(d, fb.ids);
    return r;
  }
  fb.views.assign(info->pAttachments, info->pAttachments + info->attachmentCount);
  std::vector<VkImageView> views = fb.views;
  if (ids) {
    fb.ids = makeIdImage(d, info->width, info->height, std::max(1u, info->layers));
    views.push_back(fb.ids.view);
    copy.attachmentCount = static_cast<uint32_t>(views.size());
    copy.pAttachments = views.data();
  }
  const VkResult r = d.vk.CreateFramebuffer(device, &copy, alloc, out);
  Lock lock(L().mutex());
  if (r == VK_SUCCESS) d.framebuffers[*out] = fb;
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyFramebuffer(VkDevice device, VkFramebuffer framebuffer,
                                              const VkAllocationCallbacks* alloc) {
  Device& d = dev(device);
  FramebufferInfo fb;
  {
    Lock lock(L().mutex());
    auto f = d.framebuffers.find(framebuffer);
    if (f != d.framebuffers.end()) fb = f->second, d.framebuffers.erase(f);
  }
  d.vk.DestroyFramebuffer(device, framebuffer, alloc);
  for (auto& [usages, shadow] : fb.shadows) d.vk.DestroyFramebuffer(device, shadow, nullptr);
  destroyIdImage(d, fb.ids);
}

// An imageless framebuffer whose descriptions name the usage of the images begun with: the program's
// own, or the layer's copy of it where the layer added usage to those images (depth images and the
// swapchain's are read back).
VkFramebuffer framebufferForUsage(Device& d, FramebufferInfo& fb, VkFramebuffer own, const std::vector<VkImageView>& views) {
  std::vector<VkImageUsageFlags> usages;
  bool same = true;
  for (size_t i = 0; i < fb.image_infos.size() && i < views.size(); ++i) {
    VkImageUsageFlags usage = fb.image_infos[i].usage;
    auto view = d.views.find(views[i]);
    if (view != d.views.end()) {
      auto image = d.image_usage.find(view->second.image);
      if (image != d.image_usage.end()) usage = image->second;
    }
    same &= usage == fb.image_infos[i].usage;
    usages.push_back(usage);
  }
  if (same) return own;
  VkFramebuffer& shadow = fb.shadows[usages];
  if (shadow) return shadow;
  std::vector<VkFramebufferAttachmentImageInfo> images = fb.image_infos;
  for (size_t i = 0; i < images.size(); ++i) {
    if (i < usages.size()) images[i].usage = usages[i];
    images[i].pViewFormats = fb.view_formats[i].data();
  }
  VkFramebufferAttachmentsCreateInfo described{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO};
  described.attachmentImageInfoCount = static_cast<uint32_t>(images.size());
  described.pAttachmentImageInfos = images.data();
  VkFramebufferCreateInfo create = fb.create;
  create.pNext = &described;
  if (d.vk.CreateFramebuffer(d.device, &create, nullptr, &shadow) != VK_SUCCESS) {
    fb.shadows.erase(usages);
    return own;
  }
  return shadow;
}

// What vkCmdBeginRenderPass(2) passes on: the clear values with the id attachment's (0), and for an
// imageless framebuffer the attachments with the layer's id view (VkRenderPassAttachmentBeginInfo,
// changed in place for the call; restore() puts the program's back).
struct BeginEdit {
  VkRenderPassBeginInfo copy{};
  std::vector<VkClearValue> clears;
  std::vector<VkImageView> views;
  VkRenderPassAttachmentBeginInfo* attachments = nullptr;
  VkRenderPassAttachmentBeginInfo original{};

  BeginEdit(Device& d, VkCommandBuffer cb, const VkRenderPassBeginInfo* info) : copy(*info) {
    Lock lock(L().mutex());
    Recording* r = recording(d, cb);
    if (r) {
      r->render_pass = info->renderPass;
      r->framebuffer = info->framebuffer;
      r->subpass = 0;
      r->pass = -1;
      r->pass_views.clear();
    }
    auto rp = d.render_passes.find(info->renderPass);
    const bool ids = rp != d.render_passes.end() && rp->second.id_attachment != VK_ATTACHMENT_UNUSED;
    if (ids) {
      clears.assign(info->pClearValues, info->pClearValues + info->clearValueCount);
      clears.resize(rp->second.id_attachment + 1, VkClearValue{});
      clears.back() = VkClearValue{};
      copy.clearValueCount = static_cast<uint32_t>(clears.size());
      copy.pClearValues = clears.data();
    }
    // An imageless framebuffer (with ids or not): its views' usage is what the layer made it.
    auto fb = d.framebuffers.find(info->framebuffer);
    attachments = const_cast<VkRenderPassAttachmentBeginInfo*>(findInChain<VkRenderPassAttachmentBeginInfo>(
        info->pNext, VK_STRUCTURE_TYPE_RENDER_PASS_ATTACHMENT_BEGIN_INFO));
    if (fb != d.framebuffers.end() && fb->second.imageless && attachments && !fb->second.image_infos.empty()) {
      original = *attachments;
      views.assign(attachments->pAttachments, attachments->pAttachments + attachments->attachmentCount);
      if (r) r->pass_views = views;
      if (ids && fb->second.ids.view) views.push_back(fb->second.ids.view);
      attachments->attachmentCount = static_cast<uint32_t>(views.size());
      attachments->pAttachments = views.data();
      copy.framebuffer = framebufferForUsage(d, fb->second, info->framebuffer, views);
    } else {
      attachments = nullptr;
    }
  }
  void restore() {
    if (attachments) *attachments = original;
  }
};

VKAPI_ATTR void VKAPI_CALL CmdBeginRenderPass(VkCommandBuffer cb, const VkRenderPassBeginInfo* info,
                                              VkSubpassContents contents) {
  Device& d = dev(cb);
  BeginEdit edit(d, cb, info);
  d.vk.CmdBeginRenderPass(cb, &edit.copy, contents);
  edit.restore();
}

VKAPI_ATTR void VKAPI_CALL CmdBeginRenderPass2(VkCommandBuffer cb, const VkRenderPassBeginInfo* info,
                                               const VkSubpassBeginInfo* subpass) {
  Device& d = dev(cb);
  BeginEdit edit(d, cb, info);
  d.vk.CmdBeginRenderPass2(cb, &edit.copy, subpass);
  edit.restore();
}

VKAPI_ATTR void VKAPI_CALL CmdNextSubpass(VkCommandBuffer cb, VkSubpassContents contents) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) ++r->subpass;
  }
  d.vk.CmdNextSubpass(cb, contents);
}

VKAPI_ATTR void VKAPI_CALL CmdNextSubpass2(VkCommandBuffer cb, const VkSubpassBeginInfo* begin, const VkSubpassEndInfo* end) {
  Device& d = dev(cb);
  {
    Lock lock(L().mutex());
    if (Recording* r = recording(d, cb)) ++r->subpass;
  }
  d.vk.CmdNextSubpass2(cb, begin, end);
}

// At the end of a render pass instance that drew recorded draws with ids: its depth and ids are
// copied into buffers of the layer's, read at the frame's present (and its colour, on a device
// without a swapchain: read when the frame's submission is done).
struct PassImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;  ///< where the pass left it, and leaves it again
  VkFormat format = VK_FORMAT_UNDEFINED;
};
void copyImages(Device& d, VkCommandBuffer cb, PassCapture& pc, VkImage id_image, PassImage depth, PassImage color);

// The pass's colour image to copy: its first colour attachment's, when the device has no swapchain
// and the image can be copied from.
PassImage colorToCopy(Device& d, VkImageView view, VkImageLayout layout) {
  if (!d.swapchains.empty() || !view) return {};
  auto v = d.views.find(view);
  if (v == d.views.end() || !isReadableColorFormat(v->second.format)) return {};
  auto usage = d.image_usage.find(v->second.image);
  if (usage == d.image_usage.end() || !(usage->second & VK_IMAGE_USAGE_TRANSFER_SRC_BIT)) {
    L().reportOnce("a scene colour attachment that cannot be copied from (made before the layer was loaded, or "
                   "with a format other than 8-bit RGBA/BGRA): frames without colour");
    return {};
  }
  return {v->second.image, layout, v->second.format};
}

void copyPassImages(Device& d, VkCommandBuffer cb, Recording& r) {
  if (r.pass < 0) return;
  PassCapture& pc = r.passes[static_cast<size_t>(r.pass)];
  auto fb = d.framebuffers.find(r.framebuffer);
  auto rp = d.render_passes.find(r.render_pass);
  if (fb == d.framebuffers.end() || rp == d.render_passes.end() || !fb->second.ids.image || pc.id_draws == 0) return;
  pc.width = fb->second.width, pc.height = fb->second.height;
  // The depth and colour attachments of the subpass that had the ids (the first such).
  int depth_attachment = -1, color_attachment = -1;
  for (size_t s = 0; s < rp->second.id_location.size(); ++s)
    if (rp->second.id_location[s] >= 0) {
      depth_attachment = rp->second.depth_attachment[s];
      color_attachment = rp->second.color_attachment[s];
      break;
    }
  PassImage depth, color;
  const std::vector<VkImageView>& views = fb->second.imageless ? r.pass_views : fb->second.views;
  if (depth_attachment >= 0 && static_cast<size_t>(depth_attachment) < views.size()) {
    auto view = d.views.find(views[static_cast<size_t>(depth_attachment)]);
    if (view != d.views.end() && d.depth_images.count(view->second.image)) {
      depth = {view->second.image, rp->second.final_layouts[static_cast<size_t>(depth_attachment)], view->second.format};
      pc.depth_format = view->second.format;
    }
  }
  if (color_attachment >= 0 && static_cast<size_t>(color_attachment) < views.size())
    color = colorToCopy(d, views[static_cast<size_t>(color_attachment)],
                        rp->second.final_layouts[static_cast<size_t>(color_attachment)]);
  copyImages(d, cb, pc, fb->second.ids.image, depth, color);
}

// Records the copies of a pass's ids (in COLOR_ATTACHMENT_OPTIMAL), depth and colour (each in the
// layout the pass left it in, where it is left again) into the layer's buffers, read with the frame.
void copyImages(Device& d, VkCommandBuffer cb, PassCapture& pc, VkImage id_image, PassImage depth, PassImage color) {
  const VkDeviceSize pixels = static_cast<VkDeviceSize>(pc.width) * pc.height;
  if (!L().createReadbackBuffer(d, pixels * 16, pc.id_buffer, pc.id_memory)) return;
  if (depth.image && !L().createReadbackBuffer(d, pixels * 4, pc.depth_buffer, pc.depth_memory)) depth = {};
  if (color.image && !L().createReadbackBuffer(d, pixels * 4, pc.color_buffer, pc.color_memory)) color = {};
  if (color.image) pc.color_format = color.format;

  const VkImageAspectFlags depth_aspect =
      pc.depth_format == VK_FORMAT_D16_UNORM || pc.depth_format == VK_FORMAT_D32_SFLOAT ||
              pc.depth_format == VK_FORMAT_X8_D24_UNORM_PACK32
          ? VK_IMAGE_ASPECT_DEPTH_BIT
          : VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
  std::vector<VkImageMemoryBarrier> to, back;
  to.push_back(imageBarrier(id_image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT));
  for (const auto& [image, aspect, written] :
       {std::tuple{depth, depth_aspect, VkAccessFlags(VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT)},
        std::tuple{color, VkImageAspectFlags(VK_IMAGE_ASPECT_COLOR_BIT), VkAccessFlags(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT)}}) {
    if (!image.image) continue;
    to.push_back(imageBarrier(image.image, image.layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, written,
                              VK_ACCESS_TRANSFER_READ_BIT, aspect));
    // Back to the layout the program's pass left it in.
    back.push_back(imageBarrier(image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image.layout, VK_ACCESS_TRANSFER_READ_BIT,
                                VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT, aspect));
  }
  d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, static_cast<uint32_t>(to.size()),
                          to.data());
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {pc.width, pc.height, 1};
  d.vk.CmdCopyImageToBuffer(cb, id_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.id_buffer, 1, &region);
  if (color.image)
    d.vk.CmdCopyImageToBuffer(cb, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.color_buffer, 1, &region);
  if (depth.image) {
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
    d.vk.CmdCopyImageToBuffer(cb, depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.depth_buffer, 1, &region);
  }
  if (!back.empty())
    d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                            nullptr, static_cast<uint32_t>(back.size()), back.data());
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                          nullptr);
}

void endRenderPass(Device& d, VkCommandBuffer cb) {
  Lock lock(L().mutex());
  if (Recording* r = recording(d, cb)) {
    copyPassImages(d, cb, *r);
    r->render_pass = VK_NULL_HANDLE;
    r->pass = -1;
  }
}

VKAPI_ATTR void VKAPI_CALL CmdEndRenderPass(VkCommandBuffer cb) {
  Device& d = dev(cb);
  d.vk.CmdEndRenderPass(cb);
  endRenderPass(d, cb);
}

VKAPI_ATTR void VKAPI_CALL CmdEndRenderPass2(VkCommandBuffer cb, const VkSubpassEndInfo* end) {
  Device& d = dev(cb);
  d.vk.CmdEndRenderPass2(cb, end);
  endRenderPass(d, cb);
}

// Dynamic rendering: a rendering with a single-sampled depth image of the program's gets the
// layer's id image as one more colour attachment, as pipelines made for it get the format.
VKAPI_ATTR void VKAPI_CALL CmdBeginRendering(VkCommandBuffer cb, const VkRenderingInfo* info) {
  Device& d = dev(cb);
  VkRenderingInfo copy = *info;
  std::vector<VkRenderingAttachmentInfo> colors;
  VkRenderingAttachmentInfo depth{};
  {
    Lock lock(L().mutex());
    Recording* r = recording(d, cb);
    if (r) r->rendering = false, r->pass = -1;
    const VkRenderingAttachmentInfo* program_depth = info->pDepthAttachment;
    auto view = program_depth && program_depth->imageView ? d.views.find(program_depth->imageView) : d.views.end();
    auto image = view != d.views.end() ? d.depth_images.find(view->second.image) : d.depth_images.end();
    if (r && L().capturing() && d.primitive_id && image != d.depth_images.end() && info->viewMask == 0) {
      const DepthImage& di = image->second;
      IdImage& ids = d.rendering_ids[{di.width, di.height}];
      if (!ids.image) ids = makeIdImage(d, di.width, di.height, 1);
      colors.assign(info->pColorAttachments, info->pColorAttachments + info->colorAttachmentCount);
      VkRenderingAttachmentInfo id{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      id.imageView = ids.view;
      id.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      id.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      id.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      colors.push_back(id);
      copy.colorAttachmentCount = static_cast<uint32_t>(colors.size());
      copy.pColorAttachments = colors.data();
      depth = *program_depth;
      depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;  // read back at the rendering's end
      copy.pDepthAttachment = &depth;
      r->rendering = true;
      r->rendering_ids = ids.image;
      r->rendering_depth = view->second.image;
      r->rendering_depth_layout = program_depth->imageLayout;
      r->rendering_depth_format = di.format;
      r->rendering_width = di.width;
      r->rendering_height = di.height;
      const PassImage color = info->colorAttachmentCount > 0
                                  ? colorToCopy(d, info->pColorAttachments[0].imageView, info->pColorAttachments[0].imageLayout)
                                  : PassImage{};
      r->rendering_color = color.image;
      r->rendering_color_layout = color.layout;
      r->rendering_color_format = color.format;
      // The id image enters the layout the attachment names (its contents are cleared anyway).
      const VkImageMemoryBarrier barrier = imageBarrier(ids.image, VK_IMAGE_LAYOUT_UNDEFINED,
                                                        VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, 0,
                                                        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
      d.vk.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                              VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr, 0, nullptr, 1, &barrier);
    }
  }
  d.vk.CmdBeginRendering(cb, &copy);
}

VKAPI_ATTR void VKAPI_CALL CmdEndRendering(VkCommandBuffer cb) {
  Device& d = dev(cb);
  d.vk.CmdEndRendering(cb);
  Lock lock(L().mutex());
  Recording* r = recording(d, cb);
  if (!r || !r->rendering) return;
  if (r->pass >= 0 && r->passes[static_cast<size_t>(r->pass)].id_draws > 0) {
    PassCapture& pc = r->passes[static_cast<size_t>(r->pass)];
    pc.width = r->rendering_width, pc.height = r->rendering_height;
    pc.depth_format = r->rendering_depth_format;
    copyImages(d, cb, pc, r->rendering_ids, {r->rendering_depth, r->rendering_depth_layout, r->rendering_depth_format},
               {r->rendering_color, r->rendering_color_layout, r->rendering_color_format});
  }
  r->rendering = false;
  r->pass = -1;
}

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
