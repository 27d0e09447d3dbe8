#include "viper/ground_truth/resource_census.h"

#include <algorithm>

namespace viper {

std::pair<ResourceKind, uint64_t> primaryResource(const DrawRecord& d) {
  if (d.mesh_key) return {ResourceKind::kMesh, d.mesh_key};
  for (uint64_t t : d.texture_keys)
    if (t) return {ResourceKind::kTexture, t};
  return {ResourceKind::kProgram, d.program_key};
}

const char* resourceKindName(ResourceKind kind) {
  switch (kind) {
    case ResourceKind::kMesh: return "mesh";
    case ResourceKind::kTexture: return "texture";
    default: return "program";
  }
}

Eigen::Vector3d ResourceStats::meanRgb() const {
  const double n = pixels ? static_cast<double>(pixels) : 1.0;
  return Eigen::Vector3d(rgb_sum[0] / n, rgb_sum[1] / n, rgb_sum[2] / n);
}

void ResourceCensus::add(const CaptureFrame& frame, const MeshRegistry& meshes) {
  const size_t n = frame.pixelCount();
  if (frame.draw_ids.size() != n || frame.color_rgb.size() != 3 * n) return;
  // Per draw of this frame: its pixels, colour, far-plane pixels and bounding box.
  struct DrawPixels {
    uint32_t pixels = 0, far = 0;
    double rgb[3] = {0, 0, 0};
    uint32_t x0 = ~0u, y0 = ~0u, x1 = 0, y1 = 0;
  };
  std::vector<DrawPixels> per_draw(frame.draws.size());
  const bool have_depth = frame.depth_window.size() == n;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t id = frame.draw_ids[i];
    if (id == 0 || id > frame.draws.size()) continue;
    DrawPixels& p = per_draw[id - 1];
    const uint32_t x = static_cast<uint32_t>(i % frame.width), y = static_cast<uint32_t>(i / frame.width);
    ++p.pixels;
    p.far += have_depth && !(frame.depth_window[i] < 1.0f);
    for (int c = 0; c < 3; ++c) p.rgb[c] += frame.color_rgb[3 * i + c];
    p.x0 = std::min(p.x0, x), p.y0 = std::min(p.y0, y), p.x1 = std::max(p.x1, x), p.y1 = std::max(p.y1, y);
  }
  // Per resource of this frame (several draws may share one): summed, then merged into the census.
  std::unordered_map<uint64_t, ResourceSighting> sightings[3];
  for (size_t d = 0; d < frame.draws.size(); ++d) {
    const DrawPixels& p = per_draw[d];
    if (p.pixels == 0) continue;
    const DrawRecord& draw = frame.draws[d];
    const auto [kind, key] = primaryResource(draw);
    const int k = static_cast<int>(kind);
    ResourceStats& r = by_key_[k][key];
    r.kind = kind;
    r.key = key;
    r.pixels += p.pixels;
    r.far_pixels += p.far;
    if (!draw.deformed_clip_xyzw.empty()) r.deformed_pixels += p.pixels;
    for (int c = 0; c < 3; ++c) r.rgb_sum[c] += p.rgb[c];
    const Bounds3* b = draw.mesh_key ? meshes.bounds(draw.mesh_key) : nullptr;
    if (b && (draw.matrix_flags & kHasWorld)) {
      const Eigen::Matrix4d w = draw.world.cast<double>();
      Bounds3 placed;
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d v((corner & 1) ? b->max.x() : b->min.x(), (corner & 2) ? b->max.y() : b->min.y(),
                                (corner & 4) ? b->max.z() : b->min.z());
        placed.add((w * v.homogeneous()).head<3>());
      }
      r.placed_size = r.placed_size.cwiseMax(placed.max - placed.min);
    }
    ResourceSighting& s = sightings[k][key];
    if (s.pixels == 0) s = ResourceSighting{frame.number, 0, p.x0, p.y0, p.x1, p.y1};
    s.pixels += p.pixels;
    s.x0 = std::min(s.x0, p.x0), s.y0 = std::min(s.y0, p.y0), s.x1 = std::max(s.x1, p.x1), s.y1 = std::max(s.y1, p.y1);
    total_pixels_ += p.pixels;
  }
  for (int k = 0; k < 3; ++k) {
    for (const auto& [key, s] : sightings[k]) {
      ResourceStats& r = by_key_[k][key];
      ++r.frames;
      r.best.push_back(s);
      std::sort(r.best.begin(), r.best.end(),
                [](const ResourceSighting& a, const ResourceSighting& b) { return a.pixels > b.pixels; });
      if (r.best.size() > keep_) r.best.resize(keep_);
    }
  }
}

std::vector<ResourceStats> ResourceCensus::resources() const {
  std::vector<ResourceStats> out;
  for (const auto& kind : by_key_)
    for (const auto& [key, r] : kind) out.push_back(r);
  std::sort(out.begin(), out.end(), [](const ResourceStats& a, const ResourceStats& b) {
    return a.pixels != b.pixels ? a.pixels > b.pixels : a.key < b.key;
  });
  return out;
}

ClassProposal proposeClass(const ResourceStats& r, const LabelTable* previous) {
  if (previous) {
    DrawRecord probe;
    if (r.kind == ResourceKind::kMesh) probe.mesh_key = r.key;
    else if (r.kind == ResourceKind::kTexture) probe.texture_keys.push_back(r.key);
    else probe.program_key = r.key;
    if (const uint8_t c = previous->classOf(probe)) return {c, "the previous label table"};
  }
  const double n = r.pixels ? static_cast<double>(r.pixels) : 1.0;
  if (r.far_pixels >= 0.9 * n) return {2, "drawn at the far plane"};
  if (r.deformed_pixels >= 0.5 * n) return {20, "skinned (deformed vertices)"};
  const Eigen::Vector3d rgb = r.meanRgb();
  if (rgb.y() > 1.15 * rgb.x() && rgb.y() > 1.15 * rgb.z()) return {8, "mostly green"};
  if (r.placed_size.squaredNorm() > 0.0) {
    const Eigen::Vector3d& size = r.placed_size;
    const double horizontal = std::max(size.x(), size.z()), height = size.y();
    if (horizontal > 10.0 && height < 0.05 * horizontal) return {3, "flat and wide"};
    if (height > 3.0 && horizontal < 0.25 * height) return {10, "tall and thin"};
    if (height > 4.0 && horizontal > 4.0) return {9, "large and tall"};
  }
  return {0, ""};
}

}  // namespace viper
