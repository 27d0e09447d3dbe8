// Ground truth derived from a real capture, checked against the captured program's oracle: semantic
// classes, instance ids and their stability, and the camera pose. Built twice (cmake/ground_truth.cmake):
// on the test scene and on the world, each captured at build time under the capture layer.
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/oracle.h"
#include "viper/ground_truth/oracle_labels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

namespace viper {
namespace {

struct Sequence {
  std::vector<CaptureFrame> frames;
  Oracle oracle;
  static const Sequence& get() {
    static const Sequence s = [] {
      Sequence s;
      CaptureReader reader(VIPER_TEST_SCENE_CAPTURE);
      CaptureFrame f;
      while (reader.next(f) == CaptureReader::Status::kFrame) s.frames.push_back(f);
      s.oracle = readOracle(VIPER_TEST_SCENE_ORACLE);
      return s;
    }();
    return s;
  }
  const OracleFrame& truth(const CaptureFrame& f) const {
    for (const auto& o : oracle.frames)
      if (o.number == f.number) return o;
    throw std::runtime_error("frame " + std::to_string(f.number) + " not in the oracle");
  }
};

TEST(AgainstOracle, CaptureHasEveryDrawOfTheOracle) {
  const Sequence& s = Sequence::get();
  ASSERT_GE(s.frames.size(), 20u);
  for (const auto& f : s.frames) ASSERT_EQ(f.draws.size(), s.truth(f).draws.size()) << "frame " << f.number;
}

// capture_check's reprojection on the real capture (docs/capture_layer.md): every pixel's depth is its
// triangle's, except at the far plane, where the world's sky dome is drawn (gl_Position = p.xyww):
// those pixels have no depth (NaN as published), are counted apart, and are the pixels of draws
// that have no depth anywhere (backgrounds), not of scene geometry.
TEST(AgainstOracle, DepthIsTheTrianglesExceptAtTheFarPlaneWhereOnlyABackgroundIs) {
  const Sequence& s = Sequence::get();
  MeshRegistry meshes;
  ReprojectionCheck all;
  for (const auto& f : s.frames) {
    meshes.add(f.new_meshes);
    const ReprojectionCheck c = checkReprojection(f, meshes);
    std::vector<uint8_t> with_depth(f.draws.size() + 1, 0);
    for (size_t px = 0; px < f.pixelCount(); ++px)
      if (f.depth_window[px] < 1.0f) with_depth[f.draw_ids[px]] = 1;
    size_t far_of_geometry = 0;
    for (size_t px = 0; px < f.pixelCount(); ++px)
      far_of_geometry += f.draw_ids[px] != 0 && !(f.depth_window[px] < 1.0f) && with_depth[f.draw_ids[px]];
    EXPECT_EQ(far_of_geometry, 0u) << "frame " << f.number << ": pixels at the far plane of a draw with depth elsewhere";
    all.add(c);
  }
  ASSERT_GT(all.depth_relative.size(), all.checked_pixels / 2);
  EXPECT_EQ(all.depth_relative.size() + all.far_plane_pixels, all.checked_pixels);
  EXPECT_LT(quantile(all.depth_relative, 0.99), 1e-3f) << all.far_plane_pixels << " px at the far plane";
}

TEST(AgainstOracle, SemanticAndInstanceImagesAgreeWithTheTrueObjects) {
  const Sequence& s = Sequence::get();
  OracleLabeler labeler;
  for (const auto& f : s.frames) labeler.add(f, s.truth(f));
  InstancePipeline pipeline(labeler.table());
  const std::vector<bool> things = InstancePipelineOptions::defaultThingClasses();

  uint64_t labelled = 0, semantic_ok = 0, thing_pixels = 0, agreeing = 0;
  // Per true object: (frame index, our id) of every frame it is visible in.
  std::map<uint32_t, std::vector<std::pair<size_t, int32_t>>> seen;
  std::map<int32_t, std::set<uint32_t>> objects_of_id;
  for (size_t fi = 0; fi < s.frames.size(); ++fi) {
    const CaptureFrame& f = s.frames[fi];
    const OracleFrame& truth = s.truth(f);
    const InstanceFrame out = pipeline.process(f);
    std::map<uint32_t, std::map<int32_t, uint64_t>> ids_of_object;  // this frame
    for (size_t p = 0; p < f.pixelCount(); ++p) {
      const uint32_t id = f.draw_ids[p];
      if (id == 0) continue;
      const OracleDraw& d = truth.draws[id - 1];
      ++labelled;
      semantic_ok += out.semantic[p] == d.class_id;
      if (d.class_id < things.size() && things[d.class_id]) {
        ++thing_pixels;
        ++ids_of_object[d.object_id][out.instance_ids[p]];
      } else {
        EXPECT_EQ(out.instance_ids[p], 0) << "frame " << f.number << " pixel " << p << " is stuff";
      }
    }
    for (const auto& [object, ids] : ids_of_object) {
      // All of an object's pixels carry one id, and that id is no other object's.
      EXPECT_EQ(ids.size(), 1u) << "frame " << f.number << ": true object " << object << " has " << ids.size() << " ids";
      const auto best = std::max_element(ids.begin(), ids.end(), [](auto& a, auto& b) { return a.second < b.second; });
      if (best->first != 0) agreeing += best->second;
      seen[object].push_back({fi, best->first});
      objects_of_id[best->first].insert(object);
    }
  }
  ASSERT_GT(thing_pixels, 1000u);
  EXPECT_GE(static_cast<double>(semantic_ok) / labelled, 0.999) << semantic_ok << " of " << labelled;
  EXPECT_GE(static_cast<double>(agreeing) / thing_pixels, 0.999) << agreeing << " of " << thing_pixels;
  // No identity switch: an object keeps its id from one visible frame to the next as long as the
  // gap is within the extrapolation window (TrackerOptions::extrapolate_frames, 10).
  const size_t window = static_cast<size_t>(TrackerOptions().extrapolate_frames);
  size_t switches = 0;
  for (const auto& [object, visits] : seen)
    for (size_t k = 1; k < visits.size(); ++k)
      if (visits[k].first - visits[k - 1].first <= window + 1 && visits[k].second != visits[k - 1].second) {
        ++switches;
        ADD_FAILURE() << "true object " << object << ": id " << visits[k - 1].second << " in frame index "
                      << visits[k - 1].first << " became " << visits[k].second << " in " << visits[k].first;
      }
  EXPECT_EQ(switches, 0u);
  for (const auto& [id, objects] : objects_of_id) {
    if (id == 0) continue;
    EXPECT_EQ(objects.size(), 1u) << "our id " << id << " covers " << objects.size() << " true objects";
  }
}

TEST(AgainstOracle, CameraPoseFromTheViewMatrix) {
  const Sequence& s = Sequence::get();
  double worst_m = 0, worst_rad = 0;
  for (const auto& f : s.frames) {
    const auto camera = chooseFrameCamera(f);
    ASSERT_TRUE(camera) << "frame " << f.number;
    const EgoPose pose = egoPoseFromView(camera->view, f.time_s);
    const Eigen::Isometry3d truth(s.truth(f).map_from_camera_body);
    const Eigen::Isometry3d err = truth.inverse() * pose.map_from_body;
    worst_m = std::max(worst_m, err.translation().norm());
    worst_rad = std::max(worst_rad, Eigen::AngleAxisd(err.linear()).angle());
  }
  EXPECT_LT(worst_m, 1e-4);
  EXPECT_LT(worst_rad, 1e-4);
}

}  // namespace
}  // namespace viper
