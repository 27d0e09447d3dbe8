// Camera recovery: each draw's world matrix and the frame's camera (view and projection) from the
// combinations engines pass to their shaders instead of the three matrices: model-view,
// view-projection, model-view-projection, or vertices already in world space. Pure math on the
// matrices the capture layer recorded: nothing of OpenGL or ROS.
//
// Order as in OpenGL: clip = P · V · W · vertex, with W the world (object to world), V the view
// (world to eye, the camera looking down -z) and P the projection (eye to clip).
#pragma once

#include "viper/capture/capture_frame.h"

#include <cstdint>
#include <string>
#include <vector>

namespace viper {

/// Which of a draw's matrices are known (DrawMatrices::known).
enum DrawMatrixBits : uint8_t {
  kMatWorld = 1,                 ///< W
  kMatView = 2,                  ///< V
  kMatProjection = 4,            ///< P
  kMatModelView = 8,             ///< MV = V · W
  kMatViewProjection = 16,       ///< VP = P · V
  kMatModelViewProjection = 32,  ///< MVP = P · V · W
  kMatWorldSpace = 64,           ///< the draw's vertices are in world space: W = I
};

/// The matrices of one draw: those named in `known` hold what the program passed, the others are
/// meaningless.
struct DrawMatrices {
  uint8_t known = 0;  ///< DrawMatrixBits
  GlMatrix world = GlMatrix::Identity();
  GlMatrix view = GlMatrix::Identity();
  GlMatrix projection = GlMatrix::Identity();
  GlMatrix model_view = GlMatrix::Identity();
  GlMatrix view_projection = GlMatrix::Identity();
  GlMatrix model_view_projection = GlMatrix::Identity();
};

/// Largest skew |s| / a a decomposed projection may have: OpenGL's projections have none, and one
/// with a skew is a sign that the matrix is not a camera's.
constexpr double kMaxProjectionSkew = 1e-3;
/// Largest residual max|P·V − M| / max|M| a decomposition may leave (float32 matrices leave about
/// 1e-6; an oblique near plane, as water reflections use, leaves far more).
constexpr double kMaxDecompositionResidual = 1e-4;
/// How far apart two matrices A and B may be, max|A − B| / max|B|, and still count as one: a draw's
/// given matrix B against the product of the frame's camera and the draw's world (A), and two
/// matrices derived from different draws (their float32 inputs make them differ by about 1e-6).
constexpr double kMatrixTolerance = 1e-4;

/// What decomposeViewProjection() found.
struct CameraDecomposition {
  bool ok = false;
  /// Rigid: rotation rows orthonormal with determinant +1, then the translation.
  GlMatrix view = GlMatrix::Identity();
  /// OpenGL perspective, rows (a, s, c, 0), (0, b, d, 0), (0, 0, e, f), (0, 0, -1, 0), a, b > 0.
  GlMatrix projection = GlMatrix::Identity();
  double skew = 0;      ///< |s| / a
  double residual = 0;  ///< max|P·V − M| / max|M|, M scaled so that P(3, 2) = -1
  std::string why;      ///< when !ok: what is wrong with the matrix
};

/// Splits M = P·V, a view-projection or the model-view-projection of a draw in world space, into a
/// rigid view V and an OpenGL perspective projection P (see CameraDecomposition): row 3 of M is
/// −(third row of V), which gives the camera's axis and depth offset; removing that axis from rows
/// 1 and 0 (an RQ decomposition) gives b, d and the view's second row, then a, s, c and its first;
/// row 2 gives e and f. M may carry any positive scale (it draws the same image): the result is
/// normalised to P(3, 2) = -1.
///
/// Rejected (ok false, `why` says which): non-finite values; an orthographic M (row 3 without a
/// depth term: the camera's position along its axis cannot be told from the projection's depth
/// offset); a singular M; a mirrored M, that is a left-handed camera looking down +z as in
/// Direct3D-style matrices (row 3 = (0, 0, +1, 0) · V) or a projection with one axis flipped: no
/// rigid view with a projection of this form gives it, so these are rejected, not decomposed; a
/// negated M (negative overall scale: w < 0 in front of the camera, where OpenGL clips everything);
/// a frustum behind the camera (no point in front of it has a depth within -1..1: negative near and
/// far planes); skew above kMaxProjectionSkew; a residual above kMaxDecompositionResidual (the depth
/// row not of this form, as with an oblique near plane). Infinite and reversed-depth projections are
/// of this form and accepted. (The overload in ground_truth/camera_model.h, with output arguments,
/// instead returns a left-handed camera's projection with P(3, 2) = +1, and gives no reason.)
CameraDecomposition decomposeViewProjection(const GlMatrix& m);

/// A frame's camera, as resolveFrameMatrices() found it.
struct FrameCameraResult {
  bool ok = false;  ///< the frame has a camera: both view and projection
  /// kMatView and kMatProjection: which of the two were found (both when ok).
  uint8_t known = 0;
  GlMatrix view = GlMatrix::Identity();
  GlMatrix projection = GlMatrix::Identity();
  /// How they were obtained: "view and projection" (both given), "decomposed <matrix>", or
  /// "view: <how>; projection: <how>", e.g. "view: projection⁻¹ · view-projection; projection: given".
  std::string source;
  std::string why;  ///< when !ok: what the frame lacks, or why its matrix could not be decomposed
  /// With ok: draws whose given matrices disagree (beyond kMatrixTolerance) with the frame's camera
  /// and the draw's world, e.g. a draw of another pass (shadow map, reflection, a weapon's own
  /// field of view).
  int inconsistent_draws = 0;
};

/// Picks one camera for the frame, then fills each draw's world, view and projection where they can
/// be derived, setting kMatWorld, kMatView and kMatProjection in its `known`; what the draw gave
/// itself is kept as given (a draw of another pass keeps its own view or projection).
///
/// The camera, exact sources before decompositions, each the most common value among the draws
/// (given matrices: the same 16 floats; derived ones: within kMatrixTolerance; ties: the first):
/// - V: a given view; else the model-view of world-space draws; else MV · W⁻¹ of draws whose world
///   is given;
/// - P: a given projection; else MVP · MV⁻¹ of draws that give both;
/// - with one of them known, the other from the frame's view-projection: a given VP, else the MVP
///   of world-space draws, else MVP · W⁻¹ (V = P⁻¹ · VP, P = VP · V⁻¹);
/// - with neither, that view-projection decomposed (decomposeViewProjection()).
/// A model-view of a draw whose world is unknown never stands for the view: it is V · W for an
/// unknown W. An orthographic camera resolves where its projection is given (only its
/// decomposition is impossible).
///
/// A draw's world: given; I for world-space draws; else V⁻¹ · MV; else VP⁻¹ · MVP with its own VP;
/// else V⁻¹ · P⁻¹ · MVP (its own V and P where it gave them, else the frame's). Worlds and views
/// behind a projection are solved as affine matrices (last row 0, 0, 0, 1) where one fits, which
/// keeps float32's precision, else with a general inverse (a projective world, as a planar shadow's).
FrameCameraResult resolveFrameMatrices(std::vector<DrawMatrices>& draws);

}  // namespace viper
