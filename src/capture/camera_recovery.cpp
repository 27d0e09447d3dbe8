#include "viper/capture/camera_recovery.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

namespace viper {

namespace {

using Mat4 = Eigen::Matrix4d;

// Row 3 of an orthographic camera's matrix is (0, 0, 0, 1) · V: no depth term at all. Below this
// fraction of the constant term, rounding is all there is.
constexpr double kOrthographicDepthTerm = 1e-6;
// A focal length or depth slope this much smaller than the terms it was computed from is zero
// within float32's precision: the matrix is singular.
constexpr double kSingularTerm = 1e-6;
// LU pivots this much smaller than the largest count as zero. An affine matrix is judged by its
// linear part alone (its pivots are its scales), so that a distant translation does not make it
// look singular; a projective matrix's pivots also span its translations, hence the looser bound.
constexpr double kAffinePivot = 1e-6;
constexpr double kProjectivePivot = 1e-9;

// max|a − b| / max|b|; infinite where either holds a value that is not finite.
double relativeDifference(const Mat4& a, const Mat4& b) {
  if (!a.allFinite() || !b.allFinite()) return std::numeric_limits<double>::infinity();
  const double difference = (a - b).cwiseAbs().maxCoeff();
  return difference == 0 ? 0 : difference / b.cwiseAbs().maxCoeff();
}

std::optional<Mat4> inverse(const Mat4& m) {
  if (!m.allFinite()) return std::nullopt;
  if (m.row(3) == Eigen::RowVector4d(0, 0, 0, 1)) {
    Eigen::FullPivLU<Eigen::Matrix3d> lu(m.topLeftCorner<3, 3>());
    lu.setThreshold(kAffinePivot);
    if (!lu.isInvertible()) return std::nullopt;
    Mat4 inv = Mat4::Identity();
    inv.topLeftCorner<3, 3>() = lu.inverse();
    inv.topRightCorner<3, 1>() = -inv.topLeftCorner<3, 3>() * m.topRightCorner<3, 1>();
    return inv;
  }
  Eigen::FullPivLU<Mat4> lu(m);
  lu.setThreshold(kProjectivePivot);
  if (!lu.isInvertible()) return std::nullopt;
  return Mat4(lu.inverse());
}

// A with x · A = y. Tried first: A affine (last row 0, 0, 0, 1, as views and worlds are), from
// rows 0, 1 and 3 alone, kept if it gives row 2 back. A general inverse would take A's last row
// from the difference of x's depth row and -e times its w row (in a perspective they differ by f
// alone): float32's rounding of y, divided by that difference, leaves errors near 1e-5 there.
std::optional<Mat4> solve(const Mat4& x, const Mat4& y) {
  if (!x.allFinite() || !y.allFinite()) return std::nullopt;
  Eigen::Matrix3d x3;
  x3 << x.block<2, 3>(0, 0), x.block<1, 3>(3, 0);
  Eigen::Matrix<double, 3, 4> y3;
  y3 << y.topRows<2>(), y.row(3);
  y3.col(3) -= Eigen::Vector3d(x(0, 3), x(1, 3), x(3, 3));
  Eigen::FullPivLU<Eigen::Matrix3d> lu(x3);
  lu.setThreshold(kAffinePivot);
  if (lu.isInvertible()) {
    Mat4 a = Mat4::Identity();
    a.topRows<3>() = lu.solve(y3);
    if (relativeDifference(x * a, y) <= kMatrixTolerance) return a;
  }
  const auto inv = inverse(x);
  if (!inv) return std::nullopt;
  return Mat4(*inv * y);
}

std::string number(double x) {
  std::ostringstream s;
  s.precision(3);
  s << x;
  return s.str();
}

CameraDecomposition rejected(CameraDecomposition d, const std::string& why) {
  d.ok = false;
  d.why = why;
  return d;
}

CameraDecomposition decompose(const Mat4& m) {
  CameraDecomposition out;
  if (!m.allFinite()) return rejected(out, "the matrix holds a value that is not a number (NaN or infinity)");
  const double depth_term = m.block<1, 3>(3, 0).norm();
  if (depth_term == 0 && m(3, 3) == 0)
    return rejected(out, "singular matrix: its last row is zero, so w (the perspective divide) is zero everywhere");
  if (depth_term <= kOrthographicDepthTerm * std::abs(m(3, 3)))
    return rejected(out, "orthographic projection: view and projection cannot be separated");
  // Any positive scale draws the same image; the one that makes the view's axis a unit vector is
  // the one with P(3, 2) = -1.
  const Mat4 n = m / depth_term;
  const auto row = [&n](int i) -> Eigen::Vector3d { return n.block<1, 3>(i, 0).transpose(); };
  // Row 3 of P·V is −(third row of V) whatever the projection; rows 1 and 0 are what is left of
  // them once that axis (and then the second one) is taken out.
  const Eigen::Vector3d r2 = -row(3);
  const double t2 = -n(3, 3);
  const double d = row(1).dot(r2);
  const Eigen::Vector3d b_r1 = row(1) - d * r2;
  const double b = b_r1.norm();
  if (!(b > kSingularTerm * std::max(1.0, row(1).norm())))
    return rejected(out, "singular matrix: clip y depends on nothing but depth (no vertical field of view)");
  const Eigen::Vector3d r1 = b_r1 / b;
  const double t1 = (n(1, 3) - d * t2) / b;
  const double c = row(0).dot(r2), s = row(0).dot(r1);
  const Eigen::Vector3d a_r0 = row(0) - c * r2 - s * r1;
  const double a = a_r0.norm();
  if (!(a > kSingularTerm * std::max(1.0, row(0).norm())))
    return rejected(out,
                    "singular matrix: clip x depends on nothing but clip y and depth (no horizontal field of view)");
  const Eigen::Vector3d r0 = a_r0 / a;
  const double t0 = (n(0, 3) - s * t1 - c * t2) / a;
  const double e = row(2).dot(r2);
  const double f = n(2, 3) - e * t2;
  if (!(std::abs(f) > kSingularTerm * std::max(std::abs(n(2, 3)), std::abs(e * t2))))
    return rejected(out, "singular matrix: clip depth is proportional to w, so depth does not change with distance");
  Mat4 view = Mat4::Identity(), projection = Mat4::Zero();
  view.block<1, 3>(0, 0) = r0.transpose(), view(0, 3) = t0;
  view.block<1, 3>(1, 0) = r1.transpose(), view(1, 3) = t1;
  view.block<1, 3>(2, 0) = r2.transpose(), view(2, 3) = t2;
  projection(0, 0) = a, projection(0, 1) = s, projection(0, 2) = c;
  projection(1, 1) = b, projection(1, 2) = d;
  projection(2, 2) = e, projection(2, 3) = f;
  projection(3, 2) = -1;
  out.view = view.cast<float>();
  out.projection = projection.cast<float>();
  out.skew = std::abs(s) / a;
  out.residual = relativeDifference(out.projection.cast<double>() * out.view.cast<double>(), n);
  if (!(out.residual <= kMaxDecompositionResidual))
    return rejected(out, "not an OpenGL perspective camera: projection · view differs from the matrix by " +
                             number(out.residual) + " of its largest value (its depth row leans on the image axes, "
                             "as an oblique near plane makes it)");
  // At a distance D in front of the camera, depth is -e + f / D: from -infinity or +infinity (the
  // sign of f) near the camera to -e far away, so it meets -1..1 only on these conditions.
  const bool in_front = (f < 0 && e < 1) || (f > 0 && e > -1);
  if (r0.dot(r1.cross(r2)) < 0)
    return rejected(out, in_front ? "mirrored camera: the matrix flips handedness, as a left-handed camera looking "
                                    "down +z (Direct3D-style matrices) or a projection with a flipped axis does; no "
                                    "rigid view with an OpenGL perspective projection gives it"
                                  : "negative overall scale: w is negative in front of the camera, where OpenGL "
                                    "clips everything (the negated matrix would be a camera's)");
  if (!in_front)
    return rejected(out, "the frustum lies behind the camera: no point in front of it has a depth within -1..1 "
                         "(negative near and far planes)");
  if (out.skew > kMaxProjectionSkew)
    return rejected(out, "skewed projection (skew " + number(out.skew) + ", at most " + number(kMaxProjectionSkew) +
                             "): not a camera's frustum");
  out.ok = true;
  return out;
}

// Candidates for one of the frame's matrices, from one kind of source.
struct Tier {
  std::string how;
  double tolerance;  // 0: given matrices, equal only if their 16 floats are
  std::vector<Mat4> values;

  void add(const Mat4& m) {
    if (m.allFinite()) values.push_back(m);
  }
};

struct Pick {
  Mat4 value;
  std::string how;
};

// Of the first tier that has candidates: the first member of its largest group of equal values
// (ties: the group seen first).
std::optional<Pick> mostCommon(std::initializer_list<const Tier*> tiers) {
  for (const Tier* tier : tiers) {
    std::vector<std::pair<size_t, size_t>> groups;  // first member, members
    for (size_t i = 0; i < tier->values.size(); ++i) {
      const auto same = [&](const std::pair<size_t, size_t>& g) {
        return relativeDifference(tier->values[i], tier->values[g.first]) <= tier->tolerance;
      };
      const auto g = std::find_if(groups.begin(), groups.end(), same);
      if (g == groups.end())
        groups.emplace_back(i, 1);
      else
        ++g->second;
    }
    if (groups.empty()) continue;
    const auto best = std::max_element(groups.begin(), groups.end(),
                                       [](const auto& x, const auto& y) { return x.second < y.second; });
    return Pick{tier->values[best->first], tier->how};
  }
  return std::nullopt;
}

Mat4 wide(const GlMatrix& m) { return m.cast<double>(); }

std::optional<Mat4> worldOf(const DrawMatrices& d, const std::optional<Mat4>& view,
                            const std::optional<Mat4>& projection) {
  const uint8_t k = d.known;
  if (k & kMatWorld) return wide(d.world);
  if (k & kMatWorldSpace) return Mat4::Identity();
  if ((k & kMatModelView) && view)
    if (const auto v = inverse(*view)) return Mat4(*v * wide(d.model_view));
  if (!(k & kMatModelViewProjection)) return std::nullopt;
  if (k & kMatViewProjection) return solve(wide(d.view_projection), wide(d.model_view_projection));
  if (!view || !projection) return std::nullopt;
  return solve(*projection * *view, wide(d.model_view_projection));
}

// Whether a matrix the draw gave (`given` bits) differs from what the frame's camera and the draw's
// world (once resolved) make of it.
bool disagrees(const DrawMatrices& d, uint8_t given, const Mat4& view, const Mat4& projection) {
  const auto off = [](const Mat4& expected, const GlMatrix& passed) {
    return !(relativeDifference(expected, wide(passed)) <= kMatrixTolerance);
  };
  if ((given & kMatView) && off(view, d.view)) return true;
  if ((given & kMatProjection) && off(projection, d.projection)) return true;
  if ((given & kMatViewProjection) && off(projection * view, d.view_projection)) return true;
  if (!(d.known & kMatWorld)) return false;
  const Mat4 model_view = view * wide(d.world);
  return ((given & kMatModelView) && off(model_view, d.model_view)) ||
         ((given & kMatModelViewProjection) && off(projection * model_view, d.model_view_projection));
}

// The draws' candidates for the frame's view, projection and view-projection, by kind.
struct Candidates {
  Tier views{"given", 0, {}};
  Tier world_space_model_views{"model-view of world-space draws", 0, {}};
  Tier model_views_by_world{"model-view · world⁻¹", kMatrixTolerance, {}};
  Tier projections{"given", 0, {}};
  Tier mvps_by_model_view{"model-view-projection · model-view⁻¹", kMatrixTolerance, {}};
  Tier view_projections{"view-projection", 0, {}};
  Tier world_space_mvps{"model-view-projection of world-space draws", 0, {}};
  Tier mvps_by_world{"model-view-projection · world⁻¹", kMatrixTolerance, {}};

  explicit Candidates(const std::vector<DrawMatrices>& draws) {
    for (const DrawMatrices& d : draws) {
      const uint8_t k = d.known;
      const bool mv = k & kMatModelView, mvp = k & kMatModelViewProjection;
      if (k & kMatView) views.add(wide(d.view));
      if (k & kMatProjection) projections.add(wide(d.projection));
      if (k & kMatViewProjection) view_projections.add(wide(d.view_projection));
      if (mv && mvp)
        if (const auto inv = inverse(wide(d.model_view))) mvps_by_model_view.add(wide(d.model_view_projection) * *inv);
      if (k & kMatWorld) {
        if (const auto inv = inverse(wide(d.world))) {
          if (mv) model_views_by_world.add(wide(d.model_view) * *inv);
          if (mvp) mvps_by_world.add(wide(d.model_view_projection) * *inv);
        }
      } else if (k & kMatWorldSpace) {
        if (mv) world_space_model_views.add(wide(d.model_view));
        if (mvp) world_space_mvps.add(wide(d.model_view_projection));
      }
    }
  }
};

// The frame's camera (inconsistent_draws not counted yet).
FrameCameraResult frameCamera(const std::vector<DrawMatrices>& draws) {
  const Candidates c(draws);
  FrameCameraResult result;
  std::optional<Pick> view = mostCommon({&c.views, &c.world_space_model_views, &c.model_views_by_world});
  std::optional<Pick> projection = mostCommon({&c.projections, &c.mvps_by_model_view});
  const std::optional<Pick> view_projection = mostCommon({&c.view_projections, &c.world_space_mvps, &c.mvps_by_world});
  if (view_projection && view && !projection) {
    if (const auto inv = inverse(view->value))
      projection = Pick{view_projection->value * *inv, view_projection->how + " · view⁻¹"};
    else
      result.why = "the view (" + view->how + ") is singular: no projection can be derived from it";
  } else if (view_projection && projection && !view) {
    if (const auto v = solve(projection->value, view_projection->value))
      view = Pick{*v, "projection⁻¹ · " + view_projection->how};
    else
      result.why = "the projection (" + projection->how + ") is singular: no view can be derived from it";
  } else if (view_projection && !view && !projection) {
    const CameraDecomposition split = decompose(view_projection->value);
    const std::string how = "decomposed " + view_projection->how;
    if (split.ok)
      view = Pick{wide(split.view), how}, projection = Pick{wide(split.projection), how};
    else
      result.why = how + ": " + split.why;
  }

  if (view) result.view = view->value.cast<float>(), result.known |= kMatView;
  if (projection) result.projection = projection->value.cast<float>(), result.known |= kMatProjection;
  result.ok = view && projection;
  if (result.ok && view->how == projection->how)  // both given, or both from one decomposition
    result.source = view->how == "given" ? "view and projection" : view->how;
  else if (result.ok)
    result.source = "view: " + view->how + "; projection: " + projection->how;
  else if (view)
    result.source = "view: " + view->how;
  else if (projection)
    result.source = "projection: " + projection->how;
  if (!result.ok && result.why.empty()) {
    const std::string world_known =
        "a model-view or model-view-projection of a draw whose world is known (a model-view alone is view · world "
        "with the world unknown)";
    if (view)
      result.why = "no projection: the view is known (" + view->how +
                   ") but no draw gives a projection, a view-projection, a model-view-projection with its "
                   "model-view, or a model-view-projection of a draw whose world is known";
    else if (projection)
      result.why = "no view: the projection is known (" + projection->how +
                   ") but no draw gives a view, a view-projection, or " + world_known;
    else
      result.why = "no camera: no draw gives a view, a projection or a view-projection, nor " + world_known;
  }
  return result;
}

}  // namespace

CameraDecomposition decomposeViewProjection(const GlMatrix& m) { return decompose(wide(m)); }

FrameCameraResult resolveFrameMatrices(std::vector<DrawMatrices>& draws) {
  FrameCameraResult result = frameCamera(draws);
  const std::optional<Mat4> frame_view =
      (result.known & kMatView) ? std::optional<Mat4>(wide(result.view)) : std::nullopt;
  const std::optional<Mat4> frame_projection =
      (result.known & kMatProjection) ? std::optional<Mat4>(wide(result.projection)) : std::nullopt;
  for (DrawMatrices& d : draws) {
    const uint8_t given = d.known;
    const std::optional<Mat4> own_view = (given & kMatView) ? std::optional<Mat4>(wide(d.view)) : frame_view;
    const std::optional<Mat4> own_projection =
        (given & kMatProjection) ? std::optional<Mat4>(wide(d.projection)) : frame_projection;
    if (const auto world = worldOf(d, own_view, own_projection)) d.world = world->cast<float>(), d.known |= kMatWorld;
    if (own_view) d.view = own_view->cast<float>(), d.known |= kMatView;
    if (own_projection) d.projection = own_projection->cast<float>(), d.known |= kMatProjection;
    if (result.ok && disagrees(d, given, *frame_view, *frame_projection)) ++result.inconsistent_draws;
  }
  return result;
}

}  // namespace viper
