#include "viper/core/objects.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <unordered_map>

namespace viper {
namespace {

// Hash of the exact bytes of a matrix: parts of an object are placed with bit-identical matrices.
struct MatrixKey {
  float m[16];
  bool operator==(const MatrixKey& o) const { return std::memcmp(m, o.m, sizeof(m)) == 0; }
};
struct MatrixKeyHash {
  size_t operator()(const MatrixKey& k) const {
    size_t h = 1469598103934665603ull;
    const unsigned char* p = reinterpret_cast<const unsigned char*>(k.m);
    for (size_t i = 0; i < sizeof(k.m); ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
  }
};

void sortUnique(std::vector<uint64_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace

std::vector<FrameObject> groupObjects(const CaptureFrame& frame, const LabelTable& labels,
                                      const std::vector<bool>& thing_classes, const VoteWeight& weight) {
  std::vector<FrameObject> objects;
  std::unordered_map<MatrixKey, size_t, MatrixKeyHash> by_matrix;
  for (const DrawRecord& d : frame.draws) {
    if (!(d.matrix_flags & kHasWorld)) continue;
    MatrixKey key;
    std::memcpy(key.m, d.world.data(), sizeof(key.m));
    auto [it, inserted] = by_matrix.emplace(key, objects.size());
    if (inserted) {
      objects.emplace_back();
      objects.back().world = d.world;
    }
    FrameObject& o = objects[it->second];
    o.draws.push_back(d.index);
    o.mesh_keys.push_back(d.mesh_key);
    o.texture_keys.insert(o.texture_keys.end(), d.texture_keys.begin(), d.texture_keys.end());
  }
  for (FrameObject& o : objects) {
    sortUnique(o.mesh_keys);
    sortUnique(o.texture_keys);
    std::map<uint8_t, std::pair<double, uint64_t>> votes;  // class -> (weight, visible pixels)
    for (uint32_t di : o.draws) {
      const DrawRecord& d = frame.draws[di];
      const uint8_t c = labels.classOf(d);
      if (c == 0) continue;
      votes[c].first += weight ? weight(d) : 1.0;
      votes[c].second += d.visible_pixels;
    }
    o.class_id = 0;
    std::pair<double, uint64_t> best{0.0, 0};
    for (const auto& v : votes)
      if (v.second > best) best = v.second, o.class_id = v.first;
    o.is_thing = o.class_id < thing_classes.size() && thing_classes[o.class_id];
  }
  return objects;
}

DrawAssignment assignDraws(const CaptureFrame& frame, const LabelTable& labels,
                           const std::vector<FrameObject>& objects) {
  DrawAssignment a;
  a.draw_class.resize(frame.draws.size());
  a.draw_object.assign(frame.draws.size(), -1);
  for (size_t i = 0; i < frame.draws.size(); ++i) a.draw_class[i] = labels.classOf(frame.draws[i]);
  for (size_t k = 0; k < objects.size(); ++k)
    for (uint32_t di : objects[k].draws) {
      if (di >= frame.draws.size()) continue;
      a.draw_object[di] = static_cast<int32_t>(k);
      if (objects[k].is_thing) a.draw_class[di] = objects[k].class_id;
    }
  return a;
}

void measureObjects(const CaptureFrame& frame, const DrawAssignment& a, std::vector<FrameObject>& objects) {
  for (FrameObject& o : objects) {
    o.pixel_count = 0;
    o.x_min = static_cast<int>(frame.width);
    o.y_min = static_cast<int>(frame.height);
    o.x_max = o.y_max = -1;
  }
  const uint32_t n_draws = static_cast<uint32_t>(a.draw_object.size());
  const int w = static_cast<int>(frame.width);
  // Draw ids come in runs along a row: one update per run instead of one per pixel.
  for (int y = 0; y < static_cast<int>(frame.height); ++y) {
    const uint32_t* row = frame.draw_ids.data() + static_cast<size_t>(y) * w;
    for (int x = 0; x < w;) {
      const uint32_t id = row[x];
      int end = x + 1;
      while (end < w && row[end] == id) ++end;
      if (id != 0 && id <= n_draws && a.draw_object[id - 1] >= 0) {
        FrameObject& o = objects[a.draw_object[id - 1]];
        o.pixel_count += static_cast<uint32_t>(end - x);
        o.x_min = std::min(o.x_min, x);
        o.x_max = std::max(o.x_max, end - 1);
        o.y_min = std::min(o.y_min, y);
        o.y_max = std::max(o.y_max, y);
      }
      x = end;
    }
  }
}

void renderSemantic(const CaptureFrame& frame, const DrawAssignment& a, uint8_t* out) {
  // Lookup table indexed by the draw id image value (0 = none).
  std::vector<uint8_t> lut(a.draw_class.size() + 1, 0);
  std::copy(a.draw_class.begin(), a.draw_class.end(), lut.begin() + 1);
  const uint32_t n = static_cast<uint32_t>(lut.size());
  const size_t pixels = frame.pixelCount();
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t id = frame.draw_ids[i];
    out[i] = id < n ? lut[id] : 0;
  }
}

void renderInstances(const CaptureFrame& frame, const DrawAssignment& a, const std::vector<int32_t>& object_ids,
                     int32_t* out) {
  std::vector<int32_t> lut(a.draw_object.size() + 1, 0);
  for (size_t i = 0; i < a.draw_object.size(); ++i) {
    const int32_t k = a.draw_object[i];
    lut[i + 1] = (k >= 0 && static_cast<size_t>(k) < object_ids.size()) ? object_ids[k] : 0;
  }
  const uint32_t n = static_cast<uint32_t>(lut.size());
  const size_t pixels = frame.pixelCount();
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t id = frame.draw_ids[i];
    out[i] = id < n ? lut[id] : 0;
  }
}

void renderBoundaries(const int32_t* ids, int w, int h, uint8_t* out) {
  // Branch-free per row so the compiler vectorises it; rows and columns at the border compare
  // with themselves where a neighbour is missing.
  for (int y = 0; y < h; ++y) {
    const int32_t* row = ids + static_cast<size_t>(y) * w;
    const int32_t* up = y > 0 ? row - w : row;
    const int32_t* down = y + 1 < h ? row + w : row;
    uint8_t* o = out + static_cast<size_t>(y) * w;
    if (w == 1) {
      o[0] = (row[0] != up[0] || row[0] != down[0]) ? 255 : 0;
      continue;
    }
    o[0] = (row[0] != row[1] || row[0] != up[0] || row[0] != down[0]) ? 255 : 0;
    for (int x = 1; x + 1 < w; ++x) {
      const int32_t v = row[x];
      o[x] = static_cast<uint8_t>(-static_cast<int>((v != row[x - 1]) | (v != row[x + 1]) | (v != up[x]) | (v != down[x])));
    }
    o[w - 1] = (row[w - 1] != row[w - 2] || row[w - 1] != up[w - 1] || row[w - 1] != down[w - 1]) ? 255 : 0;
  }
}

}  // namespace viper
