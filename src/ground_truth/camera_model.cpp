#include "viper/ground_truth/camera_model.h"

#include "pixel_kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace viper {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

bool hasCameraMatrices(const DrawRecord& draw) {
  return (draw.matrix_flags & kHasView) && (draw.matrix_flags & kHasProjection);
}

}  // namespace

Eigen::Matrix3d PinholeIntrinsics::K() const {
  Eigen::Matrix3d k;
  k << fx, skew, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

Eigen::Vector2d PinholeIntrinsics::project(const Eigen::Vector3d& p_optical) const {
  const Eigen::Vector3d h = K() * p_optical;
  return h.head<2>() / h.z();
}

PinholeIntrinsics intrinsicsFromGlProjection(const GlMatrix& projection, uint32_t width, uint32_t height) {
  if (width == 0 || height == 0) {
    throw std::invalid_argument("intrinsicsFromGlProjection: image size is zero");
  }
  const Eigen::Matrix4d p_raw = projection.cast<double>();
  if (!p_raw.allFinite() || !(p_raw(3, 2) < 0.0)) {
    std::ostringstream msg;
    msg << "intrinsicsFromGlProjection: not an OpenGL perspective projection (P(3,2) = " << p_raw(3, 2)
        << ", must be negative)";
    throw std::invalid_argument(msg.str());
  }
  // Scaling P does not change the picture; normalise so w_clip = -z_eye.
  const Eigen::Matrix4d p = p_raw / -p_raw(3, 2);
  const double tol = 1e-6 * p.cwiseAbs().maxCoeff();
  const double must_be_zero[] = {p(3, 0), p(3, 1), p(3, 3), p(1, 0), p(0, 3), p(1, 3)};
  for (double v : must_be_zero) {
    if (std::abs(v) > tol) {
      throw std::invalid_argument(
          "intrinsicsFromGlProjection: projection is not a pinhole perspective (non-zero entry in row 3 "
          "or a depth-dependent image shift)");
    }
  }
  // x_ndc = (P00 x + P01 y + P02 z) / -z with optical X = x, Y = -y, Z = -z, then
  // u = W (x_ndc + 1) / 2 - 0.5 and v = H (1 - y_ndc) / 2 - 0.5 (rows top-down, centers at integers).
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = width * p(0, 0) / 2.0;
  k.skew = -static_cast<double>(width) * p(0, 1) / 2.0;
  k.fy = height * p(1, 1) / 2.0;
  k.cx = width * (1.0 - p(0, 2)) / 2.0 - 0.5;
  k.cy = height * (1.0 + p(1, 2)) / 2.0 - 0.5;
  return k;
}

DepthLinearizer::DepthLinearizer(const GlMatrix& projection)
    : p22_(projection(2, 2)), p23_(projection(2, 3)), p32_(projection(3, 2)), p33_(projection(3, 3)) {}

float DepthLinearizer::toMetres(float depth_window) const {
  if (!(depth_window >= 0.0f && depth_window < 1.0f)) return kNaN;
  const double z_ndc = 2.0 * depth_window - 1.0;
  // z_ndc (P32 z + P33) = P22 z + P23, solved for z; the optical depth is -z.
  const double denom = p22_ - z_ndc * p32_;
  if (denom == 0.0) return kNaN;
  // Checked as the float it is published as (the vector kernels check 8 or 16 floats at once): a
  // distance that rounds to 0 or to infinity has no depth either.
  const float depth_m = static_cast<float>((p23_ - z_ndc * p33_) / denom);
  if (!(depth_m > 0.0f) || !(depth_m < std::numeric_limits<float>::infinity())) return kNaN;
  return depth_m;
}

std::optional<FrameCamera> chooseFrameCamera(const CaptureFrame& frame) {
  std::vector<FrameCamera> pairs;
  for (const DrawRecord& draw : frame.draws) {
    if (!hasCameraMatrices(draw)) continue;
    auto it = pairs.begin();
    for (; it != pairs.end(); ++it) {
      if (it->view == draw.view && it->projection == draw.projection) break;
    }
    if (it == pairs.end()) {
      pairs.push_back(FrameCamera{draw.view, draw.projection, 0});
      it = pairs.end() - 1;
    }
    it->visible_pixels += draw.visible_pixels;
  }
  if (pairs.empty()) return std::nullopt;
  const FrameCamera* best = &pairs.front();
  for (const FrameCamera& pair : pairs) {
    if (pair.visible_pixels > best->visible_pixels) best = &pair;
  }
  return *best;
}

namespace {

// Rows 2 and 3 of each draw's projection for the vector kernels (pixel_kernels.h), NaN where none.
struct DepthTable {
  std::vector<double> p22, p23, p32, p33;
  explicit DepthTable(size_t size) : p22(size, kNaNd), p23(size, kNaNd), p32(size, kNaNd), p33(size, kNaNd) {}
  void set(size_t slot, const std::array<double, 4>& r) {
    p22[slot] = r[0], p23[slot] = r[1], p32[slot] = r[2], p33[slot] = r[3];
  }
  pixel_kernels::DepthRows rows() const {
    return {p22.data(), p23.data(), p32.data(), p33.data(), static_cast<uint32_t>(p22.size())};
  }
  static constexpr double kNaNd = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace

std::vector<float> depthMetres(const CaptureFrame& frame, const FrameCamera* camera, Instructions instructions) {
  std::vector<float> out(frame.pixelCount());
  depthMetres(frame, camera, out.data(), instructions);
  return out;
}

void depthMetres(const CaptureFrame& frame, const FrameCamera* camera, float* out, Instructions instructions) {
  const size_t n = frame.pixelCount();
  if (frame.depth_window.size() != n) {
    std::fill(out, out + n, kNaN);
    return;
  }
  depthMetres(frame, frame.draw_ids.size() == n ? frame.draw_ids.data() : nullptr, frame.depth_window.data(), camera,
              out, instructions);
}

namespace {

// Each pixel's linearizer, by draw id (index + 1 as in the id image); slot 0 is the frame camera.
std::vector<std::optional<DepthLinearizer>> linearizersOf(const CaptureFrame& frame, const FrameCamera* camera) {
  std::vector<std::optional<DepthLinearizer>> by_id(frame.draws.size() + 1);
  if (camera) by_id[0].emplace(camera->projection);
  for (const DrawRecord& draw : frame.draws) {
    if (draw.index >= frame.draws.size()) continue;
    if (draw.matrix_flags & kHasProjection) {
      by_id[draw.index + 1].emplace(draw.projection);
    } else {
      by_id[draw.index + 1] = by_id[0];
    }
  }
  return by_id;
}

DepthTable tableOf(const std::vector<std::optional<DepthLinearizer>>& by_id) {
  DepthTable table(by_id.size());
  for (size_t id = 0; id < by_id.size(); ++id)
    if (by_id[id]) table.set(id, by_id[id]->rows());
  return table;
}

// One pixel at a time from `from`: the reference, and the pixels after the kernels' blocks (which
// write every pixel of theirs). Each pixel is read before it is written, so that `out` may be
// `depth_window`.
void metresFrom(size_t from, size_t n, const std::vector<std::optional<DepthLinearizer>>& by_id,
                const uint32_t* draw_ids, const float* depth_window, float* out) {
  for (size_t i = from; i < n; ++i) {
    uint32_t id = draw_ids ? draw_ids[i] : 0;
    if (id >= by_id.size()) id = 0;
    const auto& lin = by_id[id];
    out[i] = lin ? lin->toMetres(depth_window[i]) : kNaN;
  }
}

}  // namespace

void depthMetres(const CaptureFrame& frame, const uint32_t* draw_ids, const float* depth_window,
                 const FrameCamera* camera, float* out, Instructions instructions) {
  const size_t n = frame.pixelCount();
  const auto by_id = linearizersOf(frame, camera);
  size_t done = 0;
  const Instructions path = pixel_kernels::kernelPath(instructions);
  if (path != Instructions::kScalar)
    done = pixel_kernels::depthMetres(path, draw_ids, depth_window, n, tableOf(by_id).rows(), out);
  metresFrom(done, n, by_id, draw_ids, depth_window, out);
}

uint32_t depthMetresMaskingPrimitives(const CaptureFrame& frame, const uint32_t* draw_ids, const float* depth_window,
                                      const FrameCamera* camera, float* out, int32_t* primitives,
                                      Instructions instructions) {
  const size_t n = frame.pixelCount();
  auto* const words = reinterpret_cast<uint32_t*>(primitives);
  const auto by_id = linearizersOf(frame, camera);
  uint32_t largest = 0;
  size_t done = 0;
  const Instructions path = pixel_kernels::kernelPath(instructions);
  if (path != Instructions::kScalar)
    done = pixel_kernels::depthMetresMasking(path, draw_ids, depth_window, n, tableOf(by_id).rows(), out, primitives,
                                             largest);
  metresFrom(done, n, by_id, draw_ids, depth_window, out);
  maskPrimitiveIds(draw_ids + done, words + done, n - done, primitives + done);
  return std::max(largest, largestDrawId(draw_ids + done, n - done));
}

std::vector<float> windowDepthFromMetres(const CaptureFrame& frame, const std::vector<float>& depth_m,
                                         const GlMatrix* fallback_projection, size_t* bad_depth_pixels,
                                         Instructions instructions) {
  const size_t n = frame.pixelCount();
  if (depth_m.size() != n || frame.draw_ids.size() != n)
    throw std::invalid_argument("windowDepthFromMetres: depth or draw ids do not hold " + std::to_string(n) +
                                " pixels");
  return windowDepthFromMetres(frame.draws, frame.draw_ids.data(), depth_m.data(), n, fallback_projection,
                               bad_depth_pixels, instructions);
}

std::vector<float> windowDepthFromMetres(const std::vector<DrawRecord>& draws, const uint32_t* draw_ids,
                                         const float* depth_m, size_t n, const GlMatrix* fallback_projection,
                                         size_t* bad_depth_pixels, Instructions instructions) {
  std::vector<float> out;
  windowDepthFromMetres(draws, draw_ids, depth_m, n, fallback_projection, out, bad_depth_pixels, instructions);
  return out;
}

void windowDepthFromMetres(const std::vector<DrawRecord>& draws, const uint32_t* draw_ids, const float* depth_m,
                           size_t n, const GlMatrix* fallback_projection, std::vector<float>& out,
                           size_t* bad_depth_pixels, Instructions instructions) {
  // Rows 2 and 3 of each draw's projection (slot 0: pixels without a draw); valid = false: none.
  struct Rows {
    bool valid = false;
    double p22 = 0, p23 = 0, p32 = 0, p33 = 0;
  };
  auto rows = [](const GlMatrix& p) { return Rows{true, p(2, 2), p(2, 3), p(3, 2), p(3, 3)}; };
  std::vector<Rows> by_id(draws.size() + 1);
  const Rows fallback = fallback_projection ? rows(*fallback_projection) : Rows{};
  for (size_t i = 0; i < draws.size(); ++i)
    by_id[i + 1] = (draws[i].matrix_flags & kHasProjection) ? rows(draws[i].projection) : fallback;

  out.resize(n);
  // Per draw: pixels without usable depth, and with it. A draw with none at all is a background at
  // the far plane (a sky): its pixels have no surface, which is not an error.
  std::vector<uint32_t> bad(by_id.size(), 0), good(by_id.size(), 0);
  size_t done = 0;
  const Instructions path = pixel_kernels::kernelPath(instructions);
  if (path != Instructions::kScalar) {
    // Slot 0 stays NaN: the kernels count pixels of no draw there, and leave them at 1.
    DepthTable table(by_id.size());
    for (size_t id = 1; id < by_id.size(); ++id)
      if (by_id[id].valid) table.set(id, {by_id[id].p22, by_id[id].p23, by_id[id].p32, by_id[id].p33});
    done = pixel_kernels::windowDepth(path, draw_ids, depth_m, n, table.rows(), out.data(),
                                      good.data(), bad.data());
  }
  // One pixel at a time: the reference, and the pixels after the kernels' blocks (which write
  // every pixel of theirs).
  std::fill(out.begin() + static_cast<std::ptrdiff_t>(done), out.end(), 1.0f);
  for (size_t p = done; p < n; ++p) {
    const uint32_t id = draw_ids[p];
    if (id == 0 || id >= by_id.size()) continue;
    const Rows& r = by_id[id];
    const float m = depth_m[p];
    if (!r.valid || !(m > 0.0f) || !std::isfinite(m)) {
      ++bad[id];
      continue;
    }
    // OpenGL eye z is -depth; window depth = (z_ndc + 1) / 2 with z_ndc = (P22 z + P23) / (P32 z + P33).
    const double z = -static_cast<double>(m);
    const double z_ndc = (r.p22 * z + r.p23) / (r.p32 * z + r.p33);
    const double d = 0.5 * (z_ndc + 1.0);
    if (d >= 0.0 && d < 1.0) {
      out[p] = static_cast<float>(d);
      ++good[id];
    } else {
      ++bad[id];
    }
  }
  size_t bad_total = 0;
  for (size_t id = 1; id < bad.size(); ++id)
    if (good[id] > 0) bad_total += bad[id];
  if (bad_depth_pixels) *bad_depth_pixels = bad_total;
}

bool decomposeViewProjection(const GlMatrix& view_projection, GlMatrix& view, GlMatrix& projection,
                             double tolerance) {
  const Eigen::Matrix4d M = view_projection.cast<double>();
  if (!M.allFinite()) return false;
  // Row 3 is P32 * (R2, t2): its direction is the camera's axis, its length |P32|.
  const Eigen::Vector3d r3 = M.block<1, 3>(3, 0).transpose();
  const double p32_abs = r3.norm();
  if (!(p32_abs > 0.0)) return false;  // orthographic: not of this form
  Eigen::Vector3d axis = r3 / p32_abs;
  // Rows 0 and 1 without their component along the axis: P00 R0 and P11 R1 (no skew).
  const Eigen::Vector3d r0 = M.block<1, 3>(0, 0).transpose(), r1 = M.block<1, 3>(1, 0).transpose();
  const Eigen::Vector3d a0 = r0 - r0.dot(axis) * axis, a1 = r1 - r1.dot(axis) * axis;
  const double p00 = a0.norm(), p11 = a1.norm();
  if (!(p00 > 0.0) || !(p11 > 0.0)) return false;
  Eigen::Matrix3d R;
  R.row(0) = (a0 / p00).transpose();
  R.row(1) = (a1 / p11).transpose();
  // The sign of P32 that makes the view a rotation (not a reflection).
  double p32 = p32_abs;
  if (R.row(0).cross(R.row(1)).dot(axis) < 0.0) p32 = -p32_abs, axis = -axis;
  R.row(2) = axis.transpose();
  const double t2 = M(3, 3) / p32;
  const double p02 = r0.dot(axis), p12 = r1.dot(axis), p22 = M.block<1, 3>(2, 0).dot(axis);
  Eigen::Matrix4d V = Eigen::Matrix4d::Identity(), P = Eigen::Matrix4d::Zero();
  V.topLeftCorner<3, 3>() = R;
  V(2, 3) = t2;
  V(0, 3) = (M(0, 3) - p02 * t2) / p00;
  V(1, 3) = (M(1, 3) - p12 * t2) / p11;
  P(0, 0) = p00, P(0, 2) = p02, P(1, 1) = p11, P(1, 2) = p12, P(2, 2) = p22, P(2, 3) = M(2, 3) - p22 * t2;
  P(3, 2) = p32;
  // Of that form only if the product gives the matrix back (skew, rows 0-2 leaning on R1/R0, or a
  // depth-dependent shift would not).
  const double scale = M.cwiseAbs().maxCoeff();
  if (!((P * V - M).cwiseAbs().maxCoeff() <= tolerance * scale)) return false;
  if (!((R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-3)) return false;
  view = V.cast<float>();
  projection = P.cast<float>();
  return true;
}

Eigen::Matrix3d opticalFromGlCamera() {
  return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
}

Eigen::Isometry3d opticalFromWorld(const GlMatrix& view) {
  Eigen::Isometry3d gl_from_world = Eigen::Isometry3d::Identity();
  gl_from_world.linear() = view.topLeftCorner<3, 3>().cast<double>();
  gl_from_world.translation() = view.topRightCorner<3, 1>().cast<double>();
  Eigen::Isometry3d optical_from_gl = Eigen::Isometry3d::Identity();
  optical_from_gl.linear() = opticalFromGlCamera();
  return optical_from_gl * gl_from_world;
}

}  // namespace viper
