// The census behind labelling a program nobody annotated (VIPER labelled each rendering resource
// once): every resource a capture's visible pixels come from, with what a person needs to name it
// (pixel count, where it appears, its colour and size) and a proposed class where something can
// propose one. The label_resources tool turns it into a web page.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/label_table.h"

#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace viper {

/// Which key of a draw names it in a label table (LabelTable::classOf's order).
enum class ResourceKind : uint8_t { kMesh = 0, kTexture = 1, kProgram = 2 };
const char* resourceKindName(ResourceKind kind);
/// The key of a draw that a label table looks at first: its mesh, else its first texture, else its program.
std::pair<ResourceKind, uint64_t> primaryResource(const DrawRecord& draw);

/// A frame where a resource shows, and where.
struct ResourceSighting {
  uint64_t frame = 0;
  uint32_t pixels = 0;
  uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< bounding box of its pixels (inclusive), top row 0
};

/// One resource, as seen over the frames added to a census.
struct ResourceStats {
  ResourceKind kind = ResourceKind::kMesh;
  uint64_t key = 0;
  uint64_t pixels = 0;          ///< visible pixels over all frames
  uint32_t frames = 0;          ///< frames in which it has visible pixels
  uint64_t far_pixels = 0;      ///< of its pixels, those at the far plane (window depth 1): the sky
  uint64_t deformed_pixels = 0; ///< of its pixels, those of draws with deformed vertices (skinning)
  double rgb_sum[3] = {0, 0, 0};
  /// World-space extent (x, y, z) of one placed draw of it (its mesh's bounds under its world
  /// matrix), the largest seen; zero if never placed.
  Eigen::Vector3d placed_size = Eigen::Vector3d::Zero();
  std::vector<ResourceSighting> best;  ///< up to census's keep_sightings frames, most pixels first

  Eigen::Vector3d meanRgb() const;
};

/// A proposed class id and the reason, for a person to accept or change.
struct ClassProposal {
  uint8_t class_id = 0;  ///< 0: nothing to propose
  std::string reason;
};

/// Accumulates resources over frames. A draw's resource is the key LabelTable::classOf looks at
/// first: its mesh, else its first texture, else its program.
class ResourceCensus {
 public:
  explicit ResourceCensus(size_t keep_sightings = 3) : keep_(keep_sightings) {}
  void add(const CaptureFrame& frame, const MeshRegistry& meshes);
  /// Every resource seen, most pixels first.
  std::vector<ResourceStats> resources() const;
  uint64_t totalPixels() const { return total_pixels_; }

 private:
  size_t keep_;
  uint64_t total_pixels_ = 0;
  std::unordered_map<uint64_t, ResourceStats> by_key_[3];
};

/// A class for a resource: the one `previous` gives its key if any; else from what it looks like:
/// at the far plane (sky), deformed vertices (person), flat and wide (road), mostly green
/// (vegetation), tall and thin (infrastructure: poles, lamps), large and tall (building). World y is
/// taken as up, as OpenGL programs usually have it. Proposals are guesses for a person to check.
ClassProposal proposeClass(const ResourceStats& resource, const LabelTable* previous = nullptr);

}  // namespace viper
