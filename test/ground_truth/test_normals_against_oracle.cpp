// Normals derived from real captures of the world (five conditions), checked against the normals of
// the oracle's triangles: the triangle each pixel's ids name, built from the oracle's mesh as the
// world uploaded it, its world matrix and (skinned draws) its bones, turned into the oracle
// camera's optical frame and towards the pixel's ray. No data derived by the capture is used for
// the truth. Prints the angle error table.
#include "oracle_truth.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/normals.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace viper {
namespace {

using truth::Sequence;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// The oracle's normal of pixel (x, y): optical frame, unit, towards the camera; nullopt where the
// pixel has no analytic truth (an effect's, or a primitive id past the oracle mesh).
std::optional<Eigen::Vector3d> oracleNormal(const Sequence& s, size_t i, int x, int y) {
  const CaptureFrame& f = s.frames[i];
  const OracleFrame& t = *s.truth[i];
  const size_t p = static_cast<size_t>(y) * f.width + x;
  const OracleDraw& d = t.draws.at(f.draw_ids[p] - 1);
  if (truth::isEffect(d)) return std::nullopt;
  const OracleMesh& mesh = *s.oracle.mesh(d.mesh);
  if (f.primitive_ids[p] >= mesh.triangleCount()) return std::nullopt;
  const auto c = truth::worldTriangle(d, mesh, f.primitive_ids[p]);
  Eigen::Vector3d n = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
  if (n.dot(truth::pixelRay(t, f.width, f.height, x, y).direction) > 0.0) n = -n;
  return opticalFromGlCamera() * t.view.cast<double>().topLeftCorner<3, 3>() * n;
}

struct Errors {
  std::vector<double> rigid, skinned;  // degrees
};

// Every frame of every condition: the step's normals, the invariants of each pixel, and the angle
// to the oracle's normal where there is one.
void collect(Errors& e) {
    for (const Sequence& s : truth::sequences()) {
      MeshRegistry meshes;
      for (size_t i = 0; i < s.frames.size(); ++i) {
        const CaptureFrame& f = s.frames[i];
        meshes.add(f.new_meshes);
        const std::optional<FrameCamera> camera = chooseFrameCamera(f);
        EXPECT_TRUE(camera.has_value());
        if (!camera) continue;
        const std::vector<float> depth = depthMetres(f, &*camera);
        GroundTruthInput in;
        in.frame = f;
        in.draw_ids = f.draw_ids.data(), in.primitive_ids = f.primitive_ids.data(), in.depth_m = depth.data();
        std::vector<float> normals(3 * f.pixelCount());
        StepProblems problems;
        NormalStats stats;
        EXPECT_TRUE(NormalsStep().process(in, camera, meshes, normals.data(), problems, &stats));
        EXPECT_TRUE(problems.empty()) << s.condition << " frame " << f.number << ": " << problems.front().text;
        const PixelRays rays(*camera, f.width, f.height);
        const OracleFrame& t = *s.truth[i];
        for (int y = 0; y < static_cast<int>(f.height); ++y) {
          for (int x = 0; x < static_cast<int>(f.width); ++x) {
            const size_t p = static_cast<size_t>(y) * f.width + x;
            const Eigen::Vector3d n(normals[3 * p], normals[3 * p + 1], normals[3 * p + 2]);
            const bool surface = f.draw_ids[p] != 0 && std::isfinite(depth[p]);
            // NaN exactly where there is no surface (the world's every mesh is in the store).
            ASSERT_EQ(n.allFinite(), surface) << s.condition << " frame " << f.number << " pixel " << x << "," << y;
            if (!surface) continue;
            ASSERT_NEAR(n.norm(), 1.0, 1e-6) << s.condition << " frame " << f.number << " pixel " << x << "," << y;
            const Eigen::Vector3d ray(rays.x(x), rays.y(y), 1.0);
            ASSERT_LE(n.dot(ray), 0.0) << s.condition << " frame " << f.number << " pixel " << x << "," << y;
            const auto truth = oracleNormal(s, i, x, y);
            if (!truth) continue;
            const double angle = std::atan2(n.cross(*truth).norm(), n.dot(*truth)) * 180.0 / M_PI;
            (t.draws[f.draw_ids[p] - 1].skinned ? e.skinned : e.rigid).push_back(angle);
          }
        }
      }
    }
    std::printf("normal angle error (deg)   pixels     median       p99      p99.9        max\n");
    for (const auto& [name, v] : {std::make_pair("rigid", &e.rigid), std::make_pair("skinned", &e.skinned)})
      std::printf("%-24s %9zu %10.2e %10.2e %10.2e %10.2e\n", name, v->size(), percentile(*v, 0.5),
                  percentile(*v, 0.99), percentile(*v, 0.999), percentile(*v, 1.0));
}

const Errors& errors() {
  static const Errors all = [] {
    Errors e;
    collect(e);
    return e;
  }();
  return all;
}

TEST(NormalsAgainstOracle, RigidTrianglesMatchTheOracles) {
  const Errors& e = errors();
  ASSERT_GT(e.rigid.size(), 100000u);
  EXPECT_LE(percentile(e.rigid, 0.5), 0.01);
  // Both sides compute the same triangle from the same float positions and matrices, in double:
  // what is left is the step's float output (6e-8 rad a component, 3e-6 degrees; 5e-6 measured).
  EXPECT_LE(percentile(e.rigid, 1.0), 1e-4);
}

TEST(NormalsAgainstOracle, SkinnedTrianglesMatchTheOracles) {
  const Errors& e = errors();
  ASSERT_GT(e.skinned.size(), 10000u);
  EXPECT_LE(percentile(e.skinned, 0.5), 0.01);
  // The step's skinned triangles come from the GPU's float clip positions (the bones blended and the
  // matrices applied in float), the oracle's from the bones in double: on the walkers' triangles of
  // a few centimetres, seen from metres away, a float rounding of 1e-7 of the clip w per vertex is
  // 1e-4 to 1e-3 rad. Measured: median 1.7e-3, p99 2.2e-2, max 7.2e-2 degrees.
  EXPECT_LE(percentile(e.skinned, 0.99), 0.05);
  EXPECT_LE(percentile(e.skinned, 1.0), 0.2);
}

}  // namespace
}  // namespace viper
