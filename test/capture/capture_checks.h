// Helpers of the capture tests: a capture read whole, and the flow of its consecutive frames
// checked both ways (viper::checkFlowPair) with the printed summary the tests share.
#pragma once

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/flow.h"
#include "viper/ground_truth/scene_flow.h"

#include <gtest/gtest.h>

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

/// The scene flow a -> b against the optical flow and both depths, on pixels whose draw has the
/// frame camera's projection (a's point p lifted from a's depth with a's camera alone):
/// - reprojection_px: p + scene flow, taken into b's optical frame and projected with b's camera,
///   against the pixel plus its optical flow;
/// - depth_relative: p's depth plus the depth change against b's depth image at the target, where
///   the flow's mask says visible and the four pixels around the target show the same triangle
///   (1 / depth bilinear there: it is affine in the image over a triangle), relative to it; draws
///   without a mesh (key 0) are counted in `depth_unplaced` instead: the layer could not tell
///   whether their vertex shader moves them (SuperTuxKart's banners under the Vulkan layer, whose
///   depth changes while their matrices do not);
/// - static_relative: |scene flow| / depth of static surfaces (same mesh, same world matrix in both
///   frames): a point the world holds still does not move, whatever the camera does.
struct SceneFlowCheck {
  std::vector<float> reprojection_px, depth_relative, static_relative;
  uint64_t mask_differs = 0;  ///< values NaN where the flow is not, or finite where it is NaN
  uint64_t depth_unplaced = 0;  ///< visible pixels of draws without a mesh, left out of depth_relative

  void add(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b, const FrameCamera& ca,
           const FrameCamera& cb, const FlowField& flow, const std::vector<float>& b_depth,
           const std::vector<float>& sf) {
    const Eigen::Matrix4d unproject = ca.projection.cast<double>().inverse();
    const Eigen::Matrix4d project = cb.projection.cast<double>();
    const Eigen::Isometry3d b_from_a = opticalMotion(cb.view, ca.view);
    const Eigen::Matrix3d flip = opticalFromGlCamera();
    const uint32_t W = a.width, H = a.height;
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x) {
        const size_t p = static_cast<size_t>(y) * W + x;
        const float* v = &sf[kSceneFlowChannels * p];
        const bool has_flow = !std::isnan(flow.uv[2 * p]);
        for (size_t c = 0; c < kSceneFlowChannels; ++c) mask_differs += std::isnan(v[c]) == has_flow;
        const uint32_t id = a.draw_ids[p];
        if (!has_flow || std::isnan(v[0]) || id == 0 || id > a.draws.size()) continue;
        const DrawRecord& da = a.draws[id - 1];
        if (!(da.matrix_flags & kHasProjection) || da.projection != ca.projection) continue;
        const Eigen::Vector4d h = unproject * Eigen::Vector4d(2.0 * (x + 0.5) / W - 1.0, 1.0 - 2.0 * (y + 0.5) / H,
                                                              2.0 * a.depth_window[p] - 1.0, 1.0);
        const Eigen::Vector3d point = flip * (h.head<3>() / h.w());
        const Eigen::Vector3d moved = b_from_a * (point + Eigen::Vector3d(v[0], v[1], v[2]));
        const Eigen::Vector4d clip = project * Eigen::Vector4d(moved.x(), -moved.y(), -moved.z(), 1.0);
        const Eigen::Vector2d target((clip.x() / clip.w() + 1.0) * 0.5 * W - 0.5, (1.0 - clip.y() / clip.w()) * 0.5 * H - 0.5);
        const Eigen::Vector2d want(x + flow.uv[2 * p], y + flow.uv[2 * p + 1]);
        reprojection_px.push_back(static_cast<float>((target - want).norm()));
        const int32_t j = a_to_b[id - 1];
        const DrawRecord& db = b.draws[static_cast<size_t>(j)];
        if (da.deformed_clip_xyzw.empty() && db.deformed_clip_xyzw.empty() && da.mesh_key == db.mesh_key &&
            (da.matrix_flags & kHasWorld) && (db.matrix_flags & kHasWorld) && da.world == db.world)
          static_relative.push_back(static_cast<float>(Eigen::Vector3d(v[0], v[1], v[2]).norm() / point.z()));
        if (flow.visible[p] != 255) continue;
        const double fx = std::floor(want.x()), fy = std::floor(want.y());
        if (fx < 0 || fy < 0 || fx + 1 >= W || fy + 1 >= H) continue;
        double inverse_depth = 0.0;
        bool same = true;
        for (int k = 0; k < 4 && same; ++k) {
          const size_t q = static_cast<size_t>(fy + (k >> 1)) * W + static_cast<size_t>(fx + (k & 1));
          same = b.draw_ids[q] == static_cast<uint32_t>(j + 1) && b.primitive_ids[q] == a.primitive_ids[p] &&
                 b_depth[q] > 0.0f;
          if (same)
            inverse_depth += ((k & 1) ? want.x() - fx : 1.0 - (want.x() - fx)) *
                             ((k >> 1) ? want.y() - fy : 1.0 - (want.y() - fy)) / b_depth[q];
        }
        if (!same || !(da.deformed_clip_xyzw.empty() && db.deformed_clip_xyzw.empty())) continue;
        if (da.mesh_key == 0) {
          ++depth_unplaced;
          continue;
        }
        const double depth_b = 1.0 / inverse_depth;
        depth_relative.push_back(static_cast<float>(std::abs(point.z() + v[3] - depth_b) / depth_b));
      }
  }
  void print() const {
    std::printf("scene flow: p + scene flow projected into the next frame vs pixel + flow: median %.2e p99 %.2e max "
                "%.2e px (%zu px); depth + change vs the next depth image: median %.2e p99 %.2e (%zu px; %llu px of "
                "draws without a mesh left out); static "
                "surfaces |scene flow| / depth: median %.2e p99 %.2e max %.2e (%zu px)\n",
                quantile(reprojection_px, 0.5), quantile(reprojection_px, 0.99), quantile(reprojection_px, 1.0),
                reprojection_px.size(), quantile(depth_relative, 0.5), quantile(depth_relative, 0.99),
                depth_relative.size(), static_cast<unsigned long long>(depth_unplaced), quantile(static_relative, 0.5), quantile(static_relative, 0.99),
                quantile(static_relative, 1.0), static_relative.size());
  }
};

/// Forward and backward flow of each pair of consecutive frames (draws associated by draw order
/// and content, no tracking), checked against each other, against the next frame's colors, and
/// (static surfaces) against the camera's own motion.
/// Frames without a camera are reported in `problem`.
struct FlowSequenceCheck {
  FlowConsistencyCheck flow;
  StaticFlowCheck statics;  ///< forward flow of static surfaces against the camera's own motion
  SceneFlowCheck scene;      ///< forward scene flow against the flow and the depths
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
    scene.print();
  }
};

/// The scene flow's expectations (gtest) on a FlowSequenceCheck of a real capture: NaN exactly where
/// the flow is; p + scene flow lands where the flow does in the next frame (two float results of
/// the same double point: p99 <= 1e-3 px), at the next frame's depth (24-bit depth buffers: median
/// <= 1e-4, p99 <= 1e-3 relative); static surfaces do not move (<= 1e-6 of their depth).
inline void expectSceneFlowHolds(const FlowSequenceCheck& c) {
  const SceneFlowCheck& scene = c.scene;
  EXPECT_EQ(scene.mask_differs, 0u);
  EXPECT_GE(scene.reprojection_px.size(), c.flow.flow_pixels / 2);
  EXPECT_LE(quantile(scene.reprojection_px, 0.99), 1e-3f);
  EXPECT_LE(quantile(scene.depth_relative, 0.5), 1e-4f);
  EXPECT_LE(quantile(scene.depth_relative, 0.99), 1e-3f);
  EXPECT_GE(scene.static_relative.size(), c.flow.id_pixels / 2);
  EXPECT_LE(quantile(scene.static_relative, 1.0), 1e-6f);
}

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
    const std::vector<float> b_depth = depthMetres(b, &*cb);
    const FlowField fwd = computeFlow(a, b, a_to_b, b_depth, meshes);
    c.scene.add(a, b, a_to_b, *ca, *cb, fwd, b_depth,
                computeSceneFlow(a, b, a_to_b, meshes, opticalMotion(ca->view, cb->view), fwd));
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
