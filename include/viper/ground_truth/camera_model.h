// The camera of a captured frame: pinhole intrinsics and metric depth recovered from the OpenGL
// matrices the program passed, and the conversion from OpenGL camera axes to the optical frame.
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/instructions.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace viper {

/// Pinhole intrinsics in the ROS/OpenCV convention: optical frame (x right, y down, z forward),
/// pixel centers at integer coordinates, (0, 0) = center of the top-left pixel.
struct PinholeIntrinsics {
  uint32_t width = 0;
  uint32_t height = 0;
  double fx = 0.0;    ///< focal length in pixels along u
  double fy = 0.0;    ///< focal length in pixels along v
  double cx = 0.0;    ///< principal point u, pixels
  double cy = 0.0;    ///< principal point v, pixels
  double skew = 0.0;  ///< K(0,1); zero for every usual projection matrix

  /// The 3x3 camera matrix K.
  Eigen::Matrix3d K() const;
  /// Projects a point given in the optical frame (z > 0) to pixel coordinates (u, v).
  Eigen::Vector2d project(const Eigen::Vector3d& p_optical) const;
};

/// Intrinsics of an OpenGL perspective projection matrix `projection` (column-major, camera
/// looking down -Z, Y up, default glDepthRange/viewport covering the whole `width` x `height` image).
/// With P = projection normalised so that P(3,2) = -1:
///   fx = W*P(0,0)/2, fy = H*P(1,1)/2, cx = W*(1-P(0,2))/2 - 0.5, cy = H*(1+P(1,2))/2 - 0.5,
///   skew = -W*P(0,1)/2 (the 0.5 moves GL's pixel-corner origin to ROS's pixel-center origin).
/// Throws std::invalid_argument if `projection` is not a perspective projection (P(3,2) >= 0,
/// a non-zero P(3,0), P(3,1), P(3,3), P(1,0), P(0,3), P(1,3)) or the size is zero.
PinholeIntrinsics intrinsicsFromGlProjection(const GlMatrix& projection, uint32_t width, uint32_t height);

/// Converts OpenGL window depth in [0, 1] to metres along the optical axis (REP 118) for one
/// projection matrix, perspective or orthographic (rows 2 and 3 of P define it:
/// z_ndc = 2d - 1 = (P(2,2) z + P(2,3)) / (P(3,2) z + P(3,3)), depth = -z).
class DepthLinearizer {
 public:
  /// Precomputes the coefficients of `projection`.
  explicit DepthLinearizer(const GlMatrix& projection);
  /// Metres along the optical axis; NaN where `depth_window` >= 1 (no surface), < 0, not finite,
  /// or where the matrix maps it to a distance that is not positive and finite as a float.
  float toMetres(float depth_window) const;
  /// The coefficients: P(2,2), P(2,3), P(3,2), P(3,3).
  std::array<double, 4> rows() const { return {p22_, p23_, p32_, p33_}; }

 private:
  double p22_, p23_, p32_, p33_;
};

/// The camera of a frame: the view and projection matrices the frame's picture was rendered with.
struct FrameCamera {
  GlMatrix view = GlMatrix::Identity();
  GlMatrix projection = GlMatrix::Identity();
  /// Visible pixels of all draws that carried exactly this (view, projection) pair.
  uint64_t visible_pixels = 0;
};

/// Chooses the frame's camera. Draws carry their own view/projection matrices; among the draws
/// that have both (kHasView and kHasProjection), the (view, projection) pair carried by the most
/// visible pixels wins (pairs compared exactly; ties go to the pair seen first). If none of those
/// draws is visible, the pair of the first such draw is used. Returns nullopt when no draw has both.
std::optional<FrameCamera> chooseFrameCamera(const CaptureFrame& frame);

/// Converts the frame's window depth to metres along the optical axis (REP 118), NaN where there is
/// no surface. Each pixel is linearised with the projection of the draw that owns it (that is the
/// matrix its depth was produced with); pixels of no draw, or of a draw without a projection, use
/// `camera`'s projection, or become NaN when `camera` is null. Returns width*height values. Every
/// path of `instructions` gives the same bits.
std::vector<float> depthMetres(const CaptureFrame& frame, const FrameCamera* camera,
                               Instructions instructions = Instructions::kWidest);
/// The same into `out` (frame.pixelCount() values): a message's pixels, say.
void depthMetres(const CaptureFrame& frame, const FrameCamera* camera, float* out,
                 Instructions instructions = Instructions::kWidest);
/// The same from the window depth and draw ids at `depth_window` and `draw_ids` (frame.pixelCount()
/// values each, wherever they are stored; `draw_ids` may be null: every pixel then uses `camera`),
/// the frame giving its draws and size. `out` may be `depth_window` itself (converted in place).
void depthMetres(const CaptureFrame& frame, const uint32_t* draw_ids, const float* depth_window,
                 const FrameCamera* camera, float* out, Instructions instructions = Instructions::kWidest);
/// depthMetres() from `draw_ids` (not null) and, in the same pass over them: the primitive ids at
/// `primitives` set to -1 where the draw id is 0 (maskPrimitiveIds() in place), and their largest
/// id returned (for drawIdsProblem()). The capture bridge's three passes over a frame's ids in one
/// where AVX2 or AVX-512 runs (each pass reads 8 MB of ids a 1080p frame); every path gives the same bits.
uint32_t depthMetresMaskingPrimitives(const CaptureFrame& frame, const uint32_t* draw_ids, const float* depth_window,
                                      const FrameCamera* camera, float* out, int32_t* primitives,
                                      Instructions instructions = Instructions::kWidest);

/// Converts depth in metres along the optical axis (REP 118) back to OpenGL window depth in [0, 1],
/// the inverse of depthMetres(): each pixel with the projection of the draw that owns it (draws
/// without kHasProjection use `fallback_projection`, pixels become 1 = no surface when that is
/// null too). Pixels without a draw, and pixels whose depth is not finite or not positive, become 1.
/// `frame` supplies draws and draw ids; `depth_m` holds frame.pixelCount() values.
/// Returns the window depths and, in `bad_depth_pixels`, how many pixels of a draw had no usable
/// depth, counting only draws that have usable depth elsewhere (a draw with none at all is a
/// background at the far plane, such as a sky, and not an error). Throws std::invalid_argument when a size does not match the frame.
/// Every path of `instructions` gives the same window depths and count.
std::vector<float> windowDepthFromMetres(const CaptureFrame& frame, const std::vector<float>& depth_m,
                                         const GlMatrix* fallback_projection, size_t* bad_depth_pixels = nullptr,
                                         Instructions instructions = Instructions::kWidest);
/// The same on a frame's draws and pixels wherever they are stored (the messages they came in, say):
/// `draw_ids` and `depth_m` hold `pixels` values each.
std::vector<float> windowDepthFromMetres(const std::vector<DrawRecord>& draws, const uint32_t* draw_ids,
                                         const float* depth_m, size_t pixels, const GlMatrix* fallback_projection,
                                         size_t* bad_depth_pixels = nullptr,
                                         Instructions instructions = Instructions::kWidest);
/// The same into `out`, resized to `pixels` values: a vector kept from frame to frame keeps its
/// pages (a new 1080p one is 8 MB faulted in and filled).
void windowDepthFromMetres(const std::vector<DrawRecord>& draws, const uint32_t* draw_ids, const float* depth_m,
                           size_t pixels, const GlMatrix* fallback_projection, std::vector<float>& out,
                           size_t* bad_depth_pixels = nullptr, Instructions instructions = Instructions::kWidest);

/// Rotation from OpenGL camera axes (x right, y up, looking down -z) to the optical frame
/// (x right, y down, z forward): diag(1, -1, -1). p_optical = opticalFromGlCamera() * p_gl.
Eigen::Matrix3d opticalFromGlCamera();

/// Pose of the world in the optical frame: p_optical = result * p_world, from an OpenGL view matrix
/// (which maps world to OpenGL camera coordinates). Its inverse is the camera pose in the world.
/// Assumes `view` is rigid (rotation + translation), as view matrices are.
Eigen::Isometry3d opticalFromWorld(const GlMatrix& view);

/// Splits a combined projection * view (what programs pass as one matrix, e.g. world-view-projection
/// times the inverse world) into a rigid view (rotation with determinant +1, translation) and a
/// pinhole perspective projection: row 3 (0, 0, +-1, 0) scaled, no skew, no image shift that depends
/// on depth (the forms glFrustum, gluPerspective and Direct3D-style builders make). The sign of the
/// projection's row 3 (OpenGL's -1, left-handed +1) is whichever makes the view a proper rotation.
/// False (outputs unspecified) if the matrix is not of that form within `tolerance` (relative).
bool decomposeViewProjection(const GlMatrix& view_projection, GlMatrix& view, GlMatrix& projection,
                             double tolerance = 1e-4);

}  // namespace viper
