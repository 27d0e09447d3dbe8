#include "viper/ground_truth/amodal.h"

#include <algorithm>
#include <string>
#include <unordered_map>

namespace viper {

OcclusionLevel occlusionLevel(double visible_fraction, uint32_t amodal_pixels, const AmodalOptions& options) {
  if (amodal_pixels == 0) return OcclusionLevel::kUnknown;
  if (visible_fraction >= options.fully_visible) return OcclusionLevel::kFullyVisible;
  if (visible_fraction >= options.partly_visible) return OcclusionLevel::kPartlyOccluded;
  return OcclusionLevel::kLargelyOccluded;
}

Difficulty kittiDifficulty(int box_height_px, OcclusionLevel occlusion, double truncation) {
  const int level = static_cast<int>(occlusion);
  if (occlusion == OcclusionLevel::kUnknown) return Difficulty::kIgnored;
  if (box_height_px >= 40 && level <= 0 && truncation <= 0.15) return Difficulty::kEasy;
  if (box_height_px >= 25 && level <= 1 && truncation <= 0.30) return Difficulty::kModerate;
  if (box_height_px >= 25 && level <= 2 && truncation <= 0.50) return Difficulty::kHard;
  return Difficulty::kIgnored;
}

namespace {

// m * x in float as GLSL on Mesa computes it: column by column, one rounded multiply and add at a
// time (no fused multiply-add). Mesa evaluates `projection * view * world * position` from the
// right, P (V (W p)): with this the world's rigid draws cover exactly the pixels GL gave them.
Eigen::Vector4f glslTimes(const Eigen::Matrix4f& m, const Eigen::Vector4f& x) {
  Eigen::Vector4f r;
  for (int i = 0; i < 4; ++i) {
    float a = m(i, 0) * x[0];
    a = m(i, 1) * x[1] + a;
    a = m(i, 2) * x[2] + a;
    r[i] = m(i, 3) * x[3] + a;
  }
  return r;
}

}  // namespace

AmodalStep::AmodalStep(AmodalOptions options) : options_(options) {}

bool AmodalStep::drawObject(const CaptureFrame& frame, const TrackedObject& object, const MeshRegistry& meshes,
                            std::string& why) {
  for (uint32_t di : object.object.draws) {
    if (di >= frame.draws.size()) {
      why = "it names draw " + std::to_string(di) + " but the frame has " + std::to_string(frame.draws.size());
      return false;
    }
    const DrawRecord& d = frame.draws[di];
    const MeshRecord* mesh = meshes.find(d.mesh_key);
    if (!mesh) {
      why = "the mesh of draw " + std::to_string(di) + " never arrived";
      return false;
    }
    const size_t verts = mesh->positions_xyz.size() / 3;
    std::vector<Eigen::Vector4f> clip(verts);
    if (!d.deformed_clip_xyzw.empty()) {
      if (d.deformed_clip_xyzw.size() != 4 * verts) {
        why = "draw " + std::to_string(di) + " is deformed but has " + std::to_string(d.deformed_clip_xyzw.size() / 4) +
              " deformed vertices for a mesh of " + std::to_string(verts);
        return false;
      }
      for (size_t v = 0; v < verts; ++v) clip[v] = Eigen::Map<const Eigen::Vector4f>(&d.deformed_clip_xyzw[4 * v]);
    } else {
      const uint8_t needed = kHasWorld | kHasView | kHasProjection;
      if ((d.matrix_flags & needed) != needed || !d.world.allFinite() || !d.view.allFinite() ||
          !d.projection.allFinite()) {
        why = "draw " + std::to_string(di) + " lacks a finite world, view or projection matrix";
        return false;
      }
      for (size_t v = 0; v < verts; ++v) {
        const Eigen::Vector4f p(mesh->positions_xyz[3 * v], mesh->positions_xyz[3 * v + 1],
                                mesh->positions_xyz[3 * v + 2], 1.0f);
        clip[v] = glslTimes(d.projection, glslTimes(d.view, glslTimes(d.world, p)));
      }
    }
    const std::vector<uint32_t>& idx = mesh->indices;
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
      if (idx[t] >= verts || idx[t + 1] >= verts || idx[t + 2] >= verts) continue;
      raster_.drawClip(clip[idx[t]], clip[idx[t + 1]], clip[idx[t + 2]]);
    }
  }
  return true;
}

void AmodalStep::process(const CaptureFrame& frame, const std::vector<TrackedObject>& objects,
                         const int32_t* instance_ids, const MeshRegistry& meshes, FrameAmodal& out,
                         StepProblems& problems) {
  out.width = frame.width, out.height = frame.height;
  out.objects.clear();
  const std::string at = "(frame " + std::to_string(frame.number) + ")";
  if (!instance_ids) {
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "no_instance_ids",
                        at + ": no instance ids for the frame; no amodal masks"});
    return;
  }
  if (raster_.width() != frame.width || raster_.height() != frame.height) raster_.resize(frame.width, frame.height);

  // Each tracked object's visible box in the instance image, in one pass (runs of one id share a
  // lookup).
  std::unordered_map<int32_t, PixelBox> visible_box;
  for (const TrackedObject& o : objects)
    if (o.track_id > 0) visible_box.emplace(o.track_id, PixelBox());
  for (uint32_t y = 0; y < frame.height; ++y) {
    const int32_t* row = instance_ids + static_cast<size_t>(y) * frame.width;
    for (uint32_t x = 0; x < frame.width;) {
      const int32_t id = row[x];
      uint32_t end = x + 1;
      while (end < frame.width && row[end] == id) ++end;
      if (id > 0) {
        auto it = visible_box.find(id);
        if (it != visible_box.end()) it->second.add(static_cast<int>(x), y), it->second.add(static_cast<int>(end - 1), y);
      }
      x = end;
    }
  }

  for (const TrackedObject& o : objects) {
    if (o.track_id <= 0) continue;
    raster_.clear();
    std::string why;
    if (!drawObject(frame, o, meshes, why)) {
      problems.push_back({StepInput::kObjects, StepSeverity::kWarning, "no_amodal",
                          at + ": track " + std::to_string(o.track_id) + ": " + why + "; no amodal mask"});
      continue;
    }
    AmodalObject a;
    a.track_id = o.track_id;
    a.class_id = o.object.class_id;
    a.box = raster_.box();
    a.amodal_pixels = static_cast<uint32_t>(raster_.coveredPixels());
    if (!a.box.empty()) {
      a.mask.resize(static_cast<size_t>(a.box.width()) * a.box.height());
      for (int y = a.box.y_min; y <= a.box.y_max; ++y)
        std::copy_n(raster_.mask().begin() + static_cast<size_t>(y) * frame.width + a.box.x_min, a.box.width(),
                    a.mask.begin() + static_cast<size_t>(y - a.box.y_min) * a.box.width());
    }
    const PixelBox& vb = visible_box[o.track_id];
    for (int y = vb.y_min; y <= vb.y_max; ++y)
      for (int x = vb.x_min; x <= vb.x_max; ++x)
        if (instance_ids[static_cast<size_t>(y) * frame.width + x] == o.track_id) {
          if (raster_.mask()[static_cast<size_t>(y) * frame.width + x]) ++a.visible_pixels;
          else ++a.visible_outside;
        }
    a.visible_fraction = a.amodal_pixels > 0 ? static_cast<double>(a.visible_pixels) / a.amodal_pixels : 0.0;
    const WindowExtent& e = raster_.extent();
    a.truncation = 1.0;  // nothing in front of the camera
    if (!e.empty) {
      const double area = (e.x_max - e.x_min) * (e.y_max - e.y_min);
      const double inside = std::max(0.0, std::min(e.x_max, double(frame.width)) - std::max(e.x_min, 0.0)) *
                            std::max(0.0, std::min(e.y_max, double(frame.height)) - std::max(e.y_min, 0.0));
      a.truncation = area > 0.0 ? std::clamp(1.0 - inside / area, 0.0, 1.0) : (inside > 0.0 ? 0.0 : 1.0);
    }
    a.occlusion = occlusionLevel(a.visible_fraction, a.amodal_pixels, options_);
    a.difficulty = kittiDifficulty(a.box.height(), a.occlusion, a.truncation);
    out.objects.push_back(std::move(a));
  }
}

}  // namespace viper
