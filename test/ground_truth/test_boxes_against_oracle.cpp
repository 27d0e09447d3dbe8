// Oriented 3D boxes derived from real captures of the world (five conditions), checked against
// boxes built from the oracle alone: every vertex of the object's part meshes (skinned ones
// deformed by the oracle's bones), placed by the oracle's world matrix, bounded along the object's
// own axes (the rotation of the world matrix, its polar factor). Issue 4: corners within 1 cm.
#include "oracle_truth.h"

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/label_table.h"

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <set>

namespace viper {
namespace {

using truth::Sequence;

// The oracle's box of the object drawn by `draws` (indices into frame.draws, one object id).
OrientedBox oracleBox(const Oracle& oracle, const OracleFrame& frame, const std::vector<uint32_t>& draws) {
  const Eigen::Matrix3d linear = frame.draws[draws.front()].world.cast<double>().topLeftCorner<3, 3>();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0) rotation = -rotation;
  Bounds3 bounds;  // in the object's axes, world origin
  for (uint32_t i : draws) {
    const OracleDraw& d = frame.draws[i];
    const OracleMesh& mesh = *oracle.mesh(d.mesh);
    for (uint32_t v = 0; v < mesh.vertexCount(); ++v) bounds.add(rotation.transpose() * truth::worldVertex(d, mesh, v));
  }
  OrientedBox box;
  box.orientation = Eigen::Quaterniond(rotation);
  box.center = rotation * (0.5 * (bounds.min + bounds.max));
  box.size = bounds.max - bounds.min;
  return box;
}

TEST(BoxesAgainstOracle, CornersWithinOneCentimetreInAllConditions) {
  InstancePipelineOptions options;
  options.thing_classes = ClassTable::load(VIPER_CLASSES_CSV).instanceEvalMask();
  options.thing_classes.resize(256, false);
  options.compute_boxes = true;
  std::printf("\nBoxes vs the oracle's (corner distance, m): every thing with a box in every frame\n");
  std::printf("%-8s %8s %8s %10s %10s %12s\n", "cond", "objects", "skinned", "median_m", "max_rigid", "max_skinned");
  std::vector<double> all;
  for (const Sequence& s : truth::sequences()) {
    SCOPED_TRACE(s.condition);
    InstancePipeline pipeline(LabelTable::load(VIPER_WORLD_LABELS), options);
    std::vector<double> errors;
    double worst_skinned = 0, worst_rigid = 0;
    size_t skinned = 0;
    for (size_t i = 0; i < s.frames.size(); ++i) {
      const CaptureFrame& f = s.frames[i];
      const OracleFrame& t = *s.truth[i];
      const InstanceFrame out = pipeline.process(f);
      for (const TrackedObject& o : out.objects) {
        if (!o.object.is_thing) continue;
        ASSERT_EQ(o.box_status, BoxStatus::kOk) << "frame " << f.number << " track " << o.track_id;
        // The core's object is exactly one true object, with all of its parts.
        const uint32_t object_id = t.draws[o.object.draws.front()].object_id;
        std::vector<uint32_t> parts;
        for (const OracleDraw& d : t.draws)
          if (d.object_id == object_id) parts.push_back(d.index);
        ASSERT_EQ(o.object.draws, parts) << "frame " << f.number << ": true object " << object_id;
        const auto truth = oracleBox(s.oracle, t, parts).corners();
        const auto ours = o.box.corners();
        double worst = 0;
        for (int c = 0; c < 8; ++c) worst = std::max(worst, (truth[c] - ours[c]).norm());
        EXPECT_LE(worst, 0.01) << "frame " << f.number << ": true object " << object_id << " ("
                               << t.draws[parts.front()].mesh << ")";
        errors.push_back(worst);
        if (t.draws[parts.front()].skinned) ++skinned, worst_skinned = std::max(worst_skinned, worst);
        else worst_rigid = std::max(worst_rigid, worst);
      }
    }
    ASSERT_FALSE(errors.empty());
    std::vector<double> sorted = errors;
    std::sort(sorted.begin(), sorted.end());
    std::printf("%-8s %8zu %8zu %10.2e %10.2e %12.2e\n", s.condition.c_str(), sorted.size(), skinned,
                sorted[sorted.size() / 2], worst_rigid, worst_skinned);
    EXPECT_GT(skinned, 0u) << "no person had a box";
    all.insert(all.end(), errors.begin(), errors.end());
  }
  EXPECT_GT(all.size(), 200u);
  std::fflush(stdout);
}

}  // namespace
}  // namespace viper
