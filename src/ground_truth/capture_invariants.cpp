#include "viper/ground_truth/capture_invariants.h"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace viper {

namespace {

// The inverse of a draw's projection * view, when it has both and they are invertible.
bool inverseViewProjection(const DrawRecord& d, Eigen::Matrix4d& out) {
  constexpr uint8_t kCamera = kHasView | kHasProjection;
  if ((d.matrix_flags & kCamera) != kCamera) return false;
  const Eigen::Matrix4d pv = d.projection.cast<double>() * d.view.cast<double>();
  if (std::abs(pv.determinant()) < 1e-300) return false;
  out = pv.inverse();
  return true;
}

// The world point at the centre of pixel (col, row) (rows top first) at window depth z.
Eigen::Vector4d pixelPoint(const Eigen::Matrix4d& inverse_view_projection, uint32_t col, uint32_t row, uint32_t W,
                           uint32_t H, float window_z) {
  const Eigen::Vector4d ndc((col + 0.5) / W * 2.0 - 1.0, 1.0 - (row + 0.5) / H * 2.0, 2.0 * window_z - 1.0, 1.0);
  const Eigen::Vector4d p = inverse_view_projection * ndc;
  return p / p.w();
}

// Distance from p to the segment a-b.
double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// Distance along the view axis of window depth z under projection P: the clip w of the point on
// the axis (GL's -z_eye, or z for left-handed projections such as Irrlicht's), |z| if orthographic.
double viewDistance(const GlMatrix& P, double window_z) {
  const double ndc = 2.0 * window_z - 1.0;
  const double denominator = ndc * P(3, 2) - P(2, 2);
  if (denominator == 0.0) return std::numeric_limits<double>::quiet_NaN();
  const double z = (P(2, 3) - ndc * P(3, 3)) / denominator;  // ndc = (P22 z + P23) / (P32 z + P33)
  return P(3, 2) != 0.0f ? P(3, 2) * z + P(3, 3) : std::abs(z);
}

// A triangle's clip-space vertices clipped to the half-space w >= kNearW (the part in front of the
// camera) and projected: a convex polygon of up to four window-space vertices.
constexpr double kNearW = 1e-5;
int clipAndProject(const Eigen::Vector4f clip[3], uint32_t W, uint32_t H, Eigen::Vector2d out[4]) {
  Eigen::Vector4d poly[4];
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector4d a = clip[k].cast<double>();
    const Eigen::Vector4d b = clip[(k + 1) % 3].cast<double>();
    const bool a_in = a.w() >= kNearW, b_in = b.w() >= kNearW;
    if (a_in) poly[n++] = a;
    if (a_in != b_in) poly[n++] = a + (b - a) * ((kNearW - a.w()) / (b.w() - a.w()));
  }
  for (int k = 0; k < n; ++k)
    out[k] = Eigen::Vector2d((poly[k].x() / poly[k].w() + 1.0) * 0.5 * W, (poly[k].y() / poly[k].w() + 1.0) * 0.5 * H);
  return n;
}

}  // namespace

void ReprojectionCheck::add(const ReprojectionCheck& o) {
  pixels += o.pixels;
  scene_pixels += o.scene_pixels;
  id_pixels += o.id_pixels;
  placed_pixels += o.placed_pixels;
  checked_pixels += o.checked_pixels;
  far_plane_pixels += o.far_plane_pixels;
  distance_px.insert(distance_px.end(), o.distance_px.begin(), o.distance_px.end());
  depth_relative.insert(depth_relative.end(), o.depth_relative.begin(), o.depth_relative.end());
}

const MeshRecord* placedMesh(const DrawRecord& d, const MeshRegistry& meshes) {
  const MeshRecord* mesh = d.mesh_key ? meshes.find(d.mesh_key) : nullptr;
  if (!mesh || !(d.matrix_flags & kHasView) || !(d.matrix_flags & kHasProjection)) return nullptr;
  if (!d.deformed_clip_xyzw.empty())
    return d.deformed_clip_xyzw.size() / 4 == mesh->positions_xyz.size() / 3 ? mesh : nullptr;
  return (d.matrix_flags & kHasWorld) ? mesh : nullptr;
}

ReprojectionCheck checkReprojection(const CaptureFrame& frame, const MeshRegistry& meshes,
                                    std::vector<float>* distance_image) {
  ReprojectionCheck c;
  const uint32_t W = frame.width, H = frame.height;
  c.pixels = frame.pixelCount();
  if (distance_image) distance_image->assign(c.pixels, std::numeric_limits<float>::quiet_NaN());
  if (frame.depth_window.size() != c.pixels || frame.draw_ids.size() != c.pixels ||
      frame.primitive_ids.size() != c.pixels)
    return c;

  // Per draw: its mesh, and the transform from mesh positions to clip space (if placed).
  struct Placed {
    const MeshRecord* mesh = nullptr;
    Eigen::Matrix4f clip_from_mesh = Eigen::Matrix4f::Identity();
    const std::vector<float>* deformed = nullptr;
  };
  std::vector<Placed> placed(frame.draws.size());
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    const DrawRecord& d = frame.draws[i];
    const MeshRecord* mesh = placedMesh(d, meshes);
    if (!mesh) continue;
    if (!d.deformed_clip_xyzw.empty()) placed[i].deformed = &d.deformed_clip_xyzw;
    placed[i].mesh = mesh;
    placed[i].clip_from_mesh = d.projection * d.view * d.world;
  }

  for (uint32_t r = 0; r < H; ++r) {
    for (uint32_t col = 0; col < W; ++col) {
      const size_t px = static_cast<size_t>(r) * W + col;
      const float z = frame.depth_window[px];
      const uint32_t id = frame.draw_ids[px];
      if (!(z < 1.0f) && id == 0) continue;
      ++c.scene_pixels;
      if (id == 0 || id > frame.draws.size()) continue;
      ++c.id_pixels;
      const Placed& p = placed[id - 1];
      const uint32_t prim = frame.primitive_ids[px];
      if (!p.mesh || (static_cast<size_t>(prim) + 1) * 3 > p.mesh->indices.size()) continue;
      ++c.placed_pixels;
      Eigen::Vector4f clip[3];
      bool known = true;
      for (int k = 0; k < 3 && known; ++k) {
        const uint32_t v = p.mesh->indices[static_cast<size_t>(prim) * 3 + k];
        if (p.deformed) {
          known = (static_cast<size_t>(v) + 1) * 4 <= p.deformed->size();
          if (known) clip[k] = Eigen::Map<const Eigen::Vector4f>(p.deformed->data() + static_cast<size_t>(v) * 4);
        } else {
          known = (static_cast<size_t>(v) + 1) * 3 <= p.mesh->positions_xyz.size();
          const float* x = p.mesh->positions_xyz.data() + static_cast<size_t>(v) * 3;
          if (known) clip[k] = p.clip_from_mesh * Eigen::Vector4f(x[0], x[1], x[2], 1.0f);
        }
      }
      Eigen::Vector2d poly[4];
      const int n = known ? clipAndProject(clip, W, H, poly) : 0;
      if (n < 3) continue;  // wholly behind the camera: the pixel cannot be on it
      ++c.checked_pixels;
      // Pixel centre in window coordinates (the image's top row is the window's last).
      const Eigen::Vector2d q(col + 0.5, static_cast<double>(H - 1 - r) + 0.5);
      // Inside the convex polygon: on the same side of every edge; else the nearest edge.
      bool pos = false, neg = false;
      double distance = std::numeric_limits<double>::infinity();
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector2d& a = poly[k];
        const Eigen::Vector2d& b = poly[(k + 1) % n];
        const double side = (b.x() - a.x()) * (q.y() - a.y()) - (b.y() - a.y()) * (q.x() - a.x());
        pos |= side > 0.0;
        neg |= side < 0.0;
        distance = std::min(distance, segmentDistance(q, a, b));
      }
      if (!(pos && neg)) distance = 0.0;
      c.distance_px.push_back(static_cast<float>(distance));
      if (distance_image) (*distance_image)[px] = static_cast<float>(distance);
      if (!(z < 1.0f)) {
        ++c.far_plane_pixels;
        continue;
      }
      // The point of the triangle the pixel centre's ray meets, by its barycentrics in clip space
      // (exact, also for triangles that cross the camera plane): sum b_i (x_i - u w_i) = 0,
      // sum b_i (y_i - v w_i) = 0, sum b_i = 1; its window depth is sum b_i z_i / sum b_i w_i.
      const double u = 2.0 * q.x() / W - 1.0, v = 2.0 * q.y() / H - 1.0;
      Eigen::Matrix3d A;
      for (int k = 0; k < 3; ++k) {
        A(0, k) = static_cast<double>(clip[k].x()) - u * clip[k].w();
        A(1, k) = static_cast<double>(clip[k].y()) - v * clip[k].w();
        A(2, k) = 1.0;
      }
      const Eigen::Vector3d bary = A.fullPivLu().solve(Eigen::Vector3d(0.0, 0.0, 1.0));
      double zc = 0.0, wc = 0.0;
      for (int k = 0; k < 3; ++k) zc += bary[k] * clip[k].z(), wc += bary[k] * clip[k].w();
      if (!(wc > 0.0)) {
        c.depth_relative.push_back(std::numeric_limits<float>::quiet_NaN());
        continue;
      }
      const double zp = (zc / wc + 1.0) * 0.5;
      const GlMatrix& P = frame.draws[id - 1].projection;
      const double captured = viewDistance(P, z), predicted = viewDistance(P, zp);
      c.depth_relative.push_back(captured > 0.0 ? static_cast<float>(std::abs(predicted - captured) / captured)
                                                : std::numeric_limits<float>::quiet_NaN());
    }
  }
  return c;
}

void FlowConsistencyCheck::add(const FlowConsistencyCheck& o) {
  forward_backward_px.insert(forward_backward_px.end(), o.forward_backward_px.begin(), o.forward_backward_px.end());
  photometric_flow_sum += o.photometric_flow_sum;
  photometric_zero_sum += o.photometric_zero_sum;
  photometric_pixels += o.photometric_pixels;
  flow_pixels += o.flow_pixels;
  visible_pixels += o.visible_pixels;
  id_pixels += o.id_pixels;
}

namespace {

// Bilinear sample of an interleaved image with `channels` values per pixel at (x, y), the centre
// of pixel (i, j) being at (i, j) as flow vectors count. False outside, or where a neighbour is NaN.
template <typename T>
bool bilinear(const T* image, uint32_t w, uint32_t h, int channels, double x, double y, double* out) {
  if (!(x >= 0.0 && y >= 0.0 && x <= w - 1.0 && y <= h - 1.0)) return false;
  const uint32_t x0 = std::min(static_cast<uint32_t>(x), w - 1), y0 = std::min(static_cast<uint32_t>(y), h - 1);
  const uint32_t x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = x - x0, fy = y - y0;
  for (int c = 0; c < channels; ++c) {
    const double v00 = image[(static_cast<size_t>(y0) * w + x0) * channels + c];
    const double v10 = image[(static_cast<size_t>(y0) * w + x1) * channels + c];
    const double v01 = image[(static_cast<size_t>(y1) * w + x0) * channels + c];
    const double v11 = image[(static_cast<size_t>(y1) * w + x1) * channels + c];
    out[c] = (1 - fy) * ((1 - fx) * v00 + fx * v10) + fy * ((1 - fx) * v01 + fx * v11);
    if (std::isnan(out[c])) return false;
  }
  return true;
}

}  // namespace

FlowConsistencyCheck checkFlowPair(const CaptureFrame& a, const CaptureFrame& b, const FlowField& forward,
                                   const FlowField& backward) {
  FlowConsistencyCheck c;
  const uint32_t W = a.width, H = a.height;
  const size_t n = a.pixelCount();
  if (b.width != W || b.height != H || forward.uv.size() != 2 * n || backward.uv.size() != 2 * n ||
      forward.visible.size() != n || a.color_rgb.size() != 3 * n || b.color_rgb.size() != 3 * n ||
      a.draw_ids.size() != n)
    return c;
  for (uint32_t y = 0; y < H; ++y) {
    for (uint32_t x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      c.id_pixels += a.draw_ids[i] != 0;
      const float u = forward.uv[2 * i], v = forward.uv[2 * i + 1];
      if (std::isnan(u) || std::isnan(v)) continue;
      ++c.flow_pixels;
      const double tx = x + u, ty = y + v;
      if (!forward.visible[i] || !(tx >= 0.0 && ty >= 0.0 && tx <= W - 1.0 && ty <= H - 1.0)) continue;
      ++c.visible_pixels;
      double back[2];
      if (!bilinear(backward.uv.data(), W, H, 2, tx, ty, back)) {
        const size_t j = static_cast<size_t>(std::lround(ty)) * W + static_cast<size_t>(std::lround(tx));
        back[0] = backward.uv[2 * j], back[1] = backward.uv[2 * j + 1];
        if (std::isnan(back[0]) || std::isnan(back[1])) continue;
      }
      c.forward_backward_px.push_back(static_cast<float>(std::hypot(u + back[0], v + back[1])));
      double warped[3];
      if (!bilinear(b.color_rgb.data(), W, H, 3, tx, ty, warped)) continue;
      double flow_err = 0.0, zero_err = 0.0;
      for (int k = 0; k < 3; ++k) {
        flow_err += std::abs(warped[k] - a.color_rgb[3 * i + k]);
        zero_err += std::abs(static_cast<double>(b.color_rgb[3 * i + k]) - a.color_rgb[3 * i + k]);
      }
      c.photometric_flow_sum += flow_err / 3.0;
      c.photometric_zero_sum += zero_err / 3.0;
      ++c.photometric_pixels;
    }
  }
  return c;
}

float quantile(std::vector<float> values, double q) {
  values.erase(std::remove_if(values.begin(), values.end(), [](float v) { return std::isnan(v); }), values.end());
  if (values.empty()) return std::numeric_limits<float>::quiet_NaN();
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

void StaticFlowCheck::add(const StaticFlowCheck& o) {
  error_px.insert(error_px.end(), o.error_px.begin(), o.error_px.end());
  static_pixels += o.static_pixels;
}

StaticFlowCheck checkStaticFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                                const FlowField& forward) {
  StaticFlowCheck c;
  const uint32_t W = a.width, H = a.height;
  const size_t n = static_cast<size_t>(W) * H;
  if (forward.width != W || forward.height != H || forward.uv.size() != 2 * n || a.draw_ids.size() != n ||
      a.depth_window.size() != n || a_to_b.size() != a.draws.size())
    return c;
  // Per draw of a: a's inverse view-projection and b's view-projection, when the draw is static.
  constexpr uint8_t kCamera = kHasView | kHasProjection;
  std::vector<Eigen::Matrix4d> unproject(a.draws.size()), project(a.draws.size());
  std::vector<bool> is_static(a.draws.size(), false);
  for (size_t i = 0; i < a.draws.size(); ++i) {
    const DrawRecord& da = a.draws[i];
    const int32_t j = a_to_b[i];
    if (j < 0 || static_cast<size_t>(j) >= b.draws.size()) continue;
    const DrawRecord& db = b.draws[static_cast<size_t>(j)];
    if (!da.deformed_clip_xyzw.empty() || !db.deformed_clip_xyzw.empty() || da.mesh_key != db.mesh_key ||
        !(da.matrix_flags & kHasWorld) || !(db.matrix_flags & kHasWorld) || da.world != db.world ||
        (db.matrix_flags & kCamera) != kCamera || !inverseViewProjection(da, unproject[i]))
      continue;
    project[i] = db.projection.cast<double>() * db.view.cast<double>();
    is_static[i] = true;
  }
  for (uint32_t row = 0; row < H; ++row)
    for (uint32_t col = 0; col < W; ++col) {
      const size_t px = static_cast<size_t>(row) * W + col;
      const uint32_t id = a.draw_ids[px];
      if (id == 0 || id > a.draws.size() || !is_static[id - 1]) continue;
      ++c.static_pixels;
      const float u = forward.uv[2 * px], v = forward.uv[2 * px + 1];
      if (std::isnan(u) || std::isnan(v)) continue;
      const Eigen::Vector4d clip = project[id - 1] * pixelPoint(unproject[id - 1], col, row, W, H, a.depth_window[px]);
      if (clip.w() <= 0.0) continue;
      const double xb = (clip.x() / clip.w() + 1.0) / 2.0 * W, yb = (1.0 - clip.y() / clip.w()) / 2.0 * H;
      const double eu = xb - (col + 0.5), ev = yb - (row + 0.5);
      c.error_px.push_back(static_cast<float>(std::hypot(u - eu, v - ev)));
    }
  return c;
}

void BoxCheck::add(const BoxCheck& o) {
  objects += o.objects;
  pixels += o.pixels;
  outside_relative.insert(outside_relative.end(), o.outside_relative.begin(), o.outside_relative.end());
  if (o.worst.relative > worst.relative) worst = o.worst;
}

BoxCheck checkBoxes(const CaptureFrame& frame, const std::vector<FrameObject>& objects, const MeshRegistry& meshes) {
  BoxCheck c;
  const uint32_t W = frame.width, H = frame.height;
  const size_t n = static_cast<size_t>(W) * H;
  if (frame.draw_ids.size() != n || frame.depth_window.size() != n) return c;
  // Per draw: its object's box (index into boxes), and its inverse projection * view.
  std::vector<int32_t> box_of(frame.draws.size(), -1);
  std::vector<OrientedBox> boxes;
  for (const FrameObject& o : objects) {
    if (o.pixel_count == 0) continue;
    BoxStatus status = BoxStatus::kOk;
    const OrientedBox box = objectBox(frame, o, meshes, &status);
    if (status != BoxStatus::kOk) continue;
    for (uint32_t d : o.draws)
      if (d < frame.draws.size()) box_of[d] = static_cast<int32_t>(boxes.size());
    boxes.push_back(box);
    ++c.objects;
  }
  std::vector<Eigen::Matrix4d> unproject(frame.draws.size()), view(frame.draws.size());
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    if (box_of[i] >= 0 && !inverseViewProjection(frame.draws[i], unproject[i])) box_of[i] = -1;
    view[i] = frame.draws[i].view.cast<double>();
  }
  for (uint32_t row = 0; row < H; ++row)
    for (uint32_t col = 0; col < W; ++col) {
      const size_t px = static_cast<size_t>(row) * W + col;
      const uint32_t id = frame.draw_ids[px];
      if (id == 0 || id > frame.draws.size() || box_of[id - 1] < 0 || frame.depth_window[px] >= 1.0f) continue;
      const Eigen::Vector4d world = pixelPoint(unproject[id - 1], col, row, W, H, frame.depth_window[px]);
      const double distance = (view[id - 1] * world).head<3>().norm();
      const OrientedBox& box = boxes[static_cast<size_t>(box_of[id - 1])];
      const Eigen::Vector3d local = box.orientation.conjugate() * (world.head<3>() - box.center);
      const Eigen::Vector3d outside = (local.cwiseAbs() - box.size / 2).cwiseMax(0.0);
      ++c.pixels;
      const float relative = distance > 0.0 ? static_cast<float>(outside.norm() / distance) : 0.0f;
      c.outside_relative.push_back(relative);
      if (relative > c.worst.relative)
        c.worst = {relative, frame.number, id - 1, col, row,
                   distance > (view[id - 1] * box.center.homogeneous()).head<3>().norm()};
    }
  return c;
}

void CaptureGaps::add(const CaptureFrame& f) {
  draws += f.draws.size();
  unrecorded_draws += f.unrecorded_draws;
  for (const DrawRecord& d : f.draws) {
    no_ids += (d.gaps & kGapNoIds) != 0;
    if (d.gaps & kGapMatrixMissing) ++matrix_missing, matrix_missing_pixels += d.visible_pixels;
    if (d.gaps & kGapNoMesh) ++no_mesh, no_mesh_pixels += d.visible_pixels;
  }
}

}  // namespace viper
