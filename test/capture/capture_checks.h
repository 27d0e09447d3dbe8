// Helpers of the capture tests: a capture read whole, and the flow of its consecutive frames
// checked both ways (viper::checkFlowPair) with the printed summary the tests share.
#pragma once

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/flow.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace viper {
namespace test {

/// Every intact frame of a capture, and the meshes they name.
inline void readCapture(const std::string& path, std::vector<CaptureFrame>& frames, MeshRegistry& meshes) {
  CaptureReader reader(path);
  CaptureFrame f;
  while (reader.next(f) == CaptureReader::Status::kFrame) {
    meshes.add(f.new_meshes);
    frames.push_back(f);
  }
}

/// Forward and backward flow of each pair of consecutive frames (draws associated by draw order
/// and content, no tracking), checked against each other, against the next frame's colors, and
/// (static surfaces) against the camera's own motion.
/// Frames without a camera are reported in `problem`.
struct FlowSequenceCheck {
  FlowConsistencyCheck flow;
  StaticFlowCheck statics;  ///< forward flow of static surfaces against the camera's own motion
  std::string problem;
  /// Id pixels of a whose draw is associated with a draw of b (the same mesh, drawn again), and of
  /// those the ones with a forward flow: flow can only be defined where a draw has a counterpart
  /// (a game that rebuilds a mesh, as Minetest does with a map block whose nodes or light change,
  /// leaves its pixels without one for that pair).
  uint64_t associated_pixels = 0, associated_with_flow = 0;
  /// Share of checked pixels whose forward-backward distance is at most 0.5 px.
  double withinHalfPixel() const {
    const auto& d = flow.forward_backward_px;
    return std::count_if(d.begin(), d.end(), [](float v) { return v <= 0.5f; }) /
           static_cast<double>(std::max<size_t>(d.size(), 1));
  }
  void print() const {
    std::printf("flow: %.1f%% of id pixels have a draw in the next frame, flow defined on %.2f%% of those\n",
                100.0 * associated_pixels / std::max<uint64_t>(flow.id_pixels, 1),
                100.0 * associated_with_flow / std::max<uint64_t>(associated_pixels, 1));
    std::printf("flow: defined on %.1f%% of id pixels, forward-backward median %.2e p99 %.2e px (<= 0.5 px: %.2f%%), "
                "photometric %.2f vs %.2f without motion\n",
                100.0 * flow.flow_pixels / std::max<uint64_t>(flow.id_pixels, 1), quantile(flow.forward_backward_px, 0.5),
                quantile(flow.forward_backward_px, 0.99), 100.0 * withinHalfPixel(), flow.photometricFlow(),
                flow.photometricZero());
    std::printf("static surfaces (%.1f%% of id pixels) against the ego flow: median %.2e p99 %.2e px\n",
                100.0 * statics.static_pixels / std::max<uint64_t>(flow.id_pixels, 1), quantile(statics.error_px, 0.5),
                quantile(statics.error_px, 0.99));
  }
};

inline FlowSequenceCheck checkFlowSequence(const std::vector<CaptureFrame>& frames, const MeshRegistry& meshes) {
  FlowSequenceCheck c;
  for (size_t i = 0; i + 1 < frames.size(); ++i) {
    const CaptureFrame& a = frames[i];
    const CaptureFrame& b = frames[i + 1];
    const std::vector<int32_t> none_a(a.draws.size(), 0), none_b(b.draws.size(), 0);
    const auto ca = chooseFrameCamera(a), cb = chooseFrameCamera(b);
    if (!ca || !cb) {
      c.problem = "frame " + std::to_string(a.number) + " or the next: no camera";
      return c;
    }
    const std::vector<int32_t> a_to_b = associateDraws(a, none_a, b, none_b);
    const FlowField fwd = computeFlow(a, b, a_to_b, depthMetres(b, &*cb), meshes);
    for (size_t p = 0; p < a.draw_ids.size() && 2 * p + 1 < fwd.uv.size(); ++p) {
      const uint32_t id = a.draw_ids[p];
      if (id == 0 || id > a_to_b.size() || a_to_b[id - 1] < 0) continue;
      ++c.associated_pixels;
      c.associated_with_flow += !std::isnan(fwd.uv[2 * p]);
    }
    const FlowField bwd = computeFlow(b, a, associateDraws(b, none_b, a, none_a), depthMetres(a, &*ca), meshes);
    c.flow.add(checkFlowPair(a, b, fwd, bwd));
    c.statics.add(checkStaticFlow(a, b, a_to_b, fwd));
  }
  return c;
}

}  // namespace test
}  // namespace viper
