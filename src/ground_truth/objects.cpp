#include "viper/ground_truth/objects.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// First x in [x, w) where row[x] != id (w if none). Four ids per step where SSE2 is available.
int runEnd(const uint32_t* row, int x, int w, uint32_t id) {
#if defined(__SSE2__)
  const __m128i v = _mm_set1_epi32(static_cast<int>(id));
  for (; x + 4 <= w; x += 4) {
    const __m128i eq = _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + x)), v);
    const int same = _mm_movemask_ps(_mm_castsi128_ps(eq));
    if (same != 0xf) return x + __builtin_ctz(~same);
  }
#endif
  while (x < w && row[x] == id) ++x;
  return x;
}

// memset without a library call for the short runs that dominate busy frames: overlapping
// 8- or 4-byte stores. n > 0.
inline void fillBytes(uint8_t* p, uint8_t value, uint32_t n) {
  if (n >= 64) {
    std::memset(p, value, n);
  } else if (n >= 8) {
    const uint64_t v = 0x0101010101010101ull * value;
    for (uint32_t i = 0; i + 8 < n; i += 8) std::memcpy(p + i, &v, 8);
    std::memcpy(p + n - 8, &v, 8);
  } else if (n >= 4) {
    const uint32_t v = 0x01010101u * value;
    std::memcpy(p, &v, 4);
    std::memcpy(p + n - 4, &v, 4);
  } else {
    p[0] = value;
    p[n > 1] = value;
    p[n - 1] = value;
  }
}

// std::fill_n for the same short runs: overlapping 16-byte stores where SSE2 is available.
inline void fillInts(int32_t* p, int32_t value, uint32_t n) {
#if defined(__SSE2__)
  if (n >= 4) {
    const __m128i v = _mm_set1_epi32(value);
    for (uint32_t i = 0; i + 4 < n; i += 4) _mm_storeu_si128(reinterpret_cast<__m128i*>(p + i), v);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(p + n - 4), v);
    return;
  }
#endif
  std::fill_n(p, n, value);
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

void findDrawRuns(const CaptureFrame& frame, DrawRuns& out) {
  if (frame.draw_ids.size() != frame.pixelCount())
    throw std::invalid_argument("findDrawRuns: draw id image has " + std::to_string(frame.draw_ids.size()) +
                                " pixels, " + std::to_string(frame.pixelCount()) + " expected");
  findDrawRuns(frame, frame.draw_ids.data(), out);
}

void findDrawRuns(const CaptureFrame& frame, const uint32_t* draw_ids, DrawRuns& out) {
  out.width = frame.width;
  out.height = frame.height;
  out.runs.clear();
  const int w = static_cast<int>(frame.width);
  for (uint32_t y = 0; y < frame.height; ++y) {
    const uint32_t* row = draw_ids + static_cast<size_t>(y) * w;
    const uint32_t row_start = y * frame.width;
    for (int x = 0; x < w;) {
      const uint32_t id = row[x];
      const int end = runEnd(row, x + 1, w, id);
      out.runs.push_back({row_start + x, static_cast<uint32_t>(end - x), id, y});
      x = end;
    }
  }
}

void measureObjects(const DrawRuns& runs, const DrawAssignment& a, std::vector<FrameObject>& objects) {
  // Per draw id first (one flat table, no indirection per run), then per object.
  struct Extent {
    uint32_t pixels = 0;
    int x_min = std::numeric_limits<int>::max(), x_max = -1, y_min = std::numeric_limits<int>::max(), y_max = -1;
  };
  const uint32_t n_draws = static_cast<uint32_t>(a.draw_object.size());
  std::vector<Extent> by_id(n_draws + 1);
  for (const DrawRuns::Run& r : runs.runs) {
    if (r.id > n_draws) continue;
    Extent& e = by_id[r.id];
    const int y = static_cast<int>(r.y), x = static_cast<int>(r.start - r.y * runs.width);
    e.pixels += r.length;
    e.x_min = std::min(e.x_min, x);
    e.x_max = std::max(e.x_max, x + static_cast<int>(r.length) - 1);
    e.y_min = std::min(e.y_min, y);
    e.y_max = std::max(e.y_max, y);
  }
  for (FrameObject& o : objects) {
    o.pixel_count = 0;
    o.x_min = static_cast<int>(runs.width);
    o.y_min = static_cast<int>(runs.height);
    o.x_max = o.y_max = -1;
  }
  for (uint32_t id = 1; id <= n_draws; ++id) {
    const Extent& e = by_id[id];
    if (e.pixels == 0 || a.draw_object[id - 1] < 0) continue;
    FrameObject& o = objects[a.draw_object[id - 1]];
    o.pixel_count += e.pixels;
    o.x_min = std::min(o.x_min, e.x_min);
    o.x_max = std::max(o.x_max, e.x_max);
    o.y_min = std::min(o.y_min, e.y_min);
    o.y_max = std::max(o.y_max, e.y_max);
  }
}

void renderSemantic(const DrawRuns& runs, const DrawAssignment& a, uint8_t* out) {
  const uint32_t n = static_cast<uint32_t>(a.draw_class.size());
  for (const DrawRuns::Run& r : runs.runs)
    fillBytes(out + r.start, r.id != 0 && r.id <= n ? a.draw_class[r.id - 1] : 0, r.length);
}

void renderRgbOfDraws(const DrawRuns& runs, const std::vector<std::array<uint8_t, 3>>& colors,
                      std::array<uint8_t, 3> other, uint8_t* rgb) {
  // Each color repeated over 16 pixels (48 bytes, whole pixels), copied in blocks of 48 or 12 bytes;
  // the last block of a run ends at the run's end, overlapping the one before.
  constexpr size_t kBlock = 48;
  std::vector<uint8_t> patterns((colors.size() + 1) * kBlock);
  for (size_t id = 0; id <= colors.size(); ++id) {
    const std::array<uint8_t, 3>& c = id < colors.size() ? colors[id] : other;
    for (size_t b = 0; b < kBlock; ++b) patterns[id * kBlock + b] = c[b % 3];
  }
  for (const DrawRuns::Run& r : runs.runs) {
    const uint8_t* pattern = patterns.data() + std::min<size_t>(r.id, colors.size()) * kBlock;
    uint8_t* out = rgb + 3 * size_t{r.start};
    const size_t bytes = 3 * size_t{r.length};
    if (bytes >= kBlock) {
      for (size_t i = 0; i + kBlock < bytes; i += kBlock) std::memcpy(out + i, pattern, kBlock);
      std::memcpy(out + bytes - kBlock, pattern, kBlock);
    } else if (bytes >= 12) {
      for (size_t i = 0; i + 12 < bytes; i += 12) std::memcpy(out + i, pattern, 12);
      std::memcpy(out + bytes - 12, pattern, 12);
    } else {
      std::memcpy(out, pattern, bytes);
    }
  }
}

std::vector<int32_t> instanceOfDraws(const DrawAssignment& a, const std::vector<int32_t>& object_ids) {
  std::vector<int32_t> lut(a.draw_object.size() + 1, 0);
  for (size_t i = 0; i < a.draw_object.size(); ++i) {
    const int32_t k = a.draw_object[i];
    lut[i + 1] = (k >= 0 && static_cast<size_t>(k) < object_ids.size()) ? object_ids[k] : 0;
  }
  return lut;
}

void renderInstances(const DrawRuns& runs, const std::vector<int32_t>& instance_of_draw, int32_t* out) {
  const size_t n = instance_of_draw.size();
  for (const DrawRuns::Run& r : runs.runs) fillInts(out + r.start, r.id < n ? instance_of_draw[r.id] : 0, r.length);
}

namespace {

// A row's pixels x0..x1-1 of one instance (neighbouring runs of the same instance merged).
struct Span {
  uint32_t x0, x1;
  int32_t instance;
};

// The spans of the runs runs[*at..] of row y (advancing *at past them).
void rowSpans(const DrawRuns& runs, const std::vector<int32_t>& instance_of_draw, uint32_t y, size_t* at,
              std::vector<Span>& spans) {
  spans.clear();
  const size_t n = instance_of_draw.size();
  const uint32_t row_start = y * runs.width;
  for (; *at < runs.runs.size() && runs.runs[*at].y == y; ++*at) {
    const DrawRuns::Run& r = runs.runs[*at];
    const int32_t instance = r.id < n ? instance_of_draw[r.id] : 0;
    const uint32_t x0 = r.start - row_start, x1 = x0 + r.length;
    if (!spans.empty() && spans.back().instance == instance) spans.back().x1 = x1;
    else spans.push_back({x0, x1, instance});
  }
}

// 255 over the pixels where `row` and its neighbour row `other` hold different instances.
void markAgainst(const std::vector<Span>& row, const std::vector<Span>& other, uint8_t* out) {
  size_t j = 0;
  for (const Span& a : row) {
    while (j < other.size() && other[j].x1 <= a.x0) ++j;
    for (size_t k = j; k < other.size() && other[k].x0 < a.x1; ++k) {
      if (other[k].instance == a.instance) continue;
      const uint32_t x0 = std::max(a.x0, other[k].x0), x1 = std::min(a.x1, other[k].x1);
      std::memset(out + x0, 255, x1 - x0);
    }
  }
}

}  // namespace

void renderBoundariesOfRuns(const DrawRuns& runs, const std::vector<int32_t>& instance_of_draw, uint8_t* out) {
  const uint32_t w = runs.width, h = runs.height;
  std::vector<Span> up, row, down;
  size_t at = 0;  // the first run of the row after the spans in `down`
  if (h > 0) rowSpans(runs, instance_of_draw, 0, &at, down);
  for (uint32_t y = 0; y < h; ++y) {
    std::swap(up, row);
    std::swap(row, down);
    if (y + 1 < h) rowSpans(runs, instance_of_draw, y + 1, &at, down);
    uint8_t* o = out + static_cast<size_t>(y) * w;
    std::memset(o, 0, w);
    for (size_t k = 1; k < row.size(); ++k) o[row[k].x0 - 1] = o[row[k].x0] = 255;  // the instance changes
    if (y > 0) markAgainst(row, up, o);
    if (y + 1 < h) markAgainst(row, down, o);
  }
}

}  // namespace viper
