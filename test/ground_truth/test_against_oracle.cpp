// Ground truth derived from a real capture of the test scene, checked against the scene's oracle:
// semantic classes, instance ids and their stability, and the camera pose. The capture and oracle
// are made at build time by running test_scene under the capture layer (cmake/ground_truth.cmake).
#include "viper/core/camera_model.h"
#include "viper/core/capture_stream.h"
#include "viper/core/ego_motion.h"
#include "viper/core/instance_pipeline.h"
#include "viper/core/oracle.h"
#include "viper/core/oracle_labels.h"

#include <gtest/gtest.h>

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

TEST(AgainstOracle, SemanticAndInstanceImagesAgreeWithTheTrueObjects) {
  const Sequence& s = Sequence::get();
  OracleLabeler labeler;
  for (const auto& f : s.frames) labeler.add(f, s.truth(f));
  InstancePipeline pipeline(labeler.table());
  const std::vector<bool> things = InstancePipelineOptions::defaultThingClasses();

  uint64_t labelled = 0, semantic_ok = 0, thing_pixels = 0;
  std::map<std::pair<int32_t, uint32_t>, uint64_t> pairs;  // (our id, true object) -> pixels
  std::map<uint32_t, std::set<int32_t>> ids_of_object;
  for (const auto& f : s.frames) {
    const OracleFrame& truth = s.truth(f);
    const InstanceFrame out = pipeline.process(f);
    for (size_t p = 0; p < f.pixelCount(); ++p) {
      const uint32_t id = f.draw_ids[p];
      if (id == 0) continue;
      const OracleDraw& d = truth.draws[id - 1];
      ++labelled;
      semantic_ok += out.semantic[p] == d.class_id;
      if (d.class_id < things.size() && things[d.class_id]) {
        ++thing_pixels;
        ++pairs[{out.instance_ids[p], d.object_id}];
        ids_of_object[d.object_id].insert(out.instance_ids[p]);
      } else {
        EXPECT_EQ(out.instance_ids[p], 0) << "frame " << f.number << " pixel " << p << " is stuff";
      }
    }
  }
  ASSERT_GT(thing_pixels, 1000u);
  EXPECT_GE(static_cast<double>(semantic_ok) / labelled, 0.999) << semantic_ok << " of " << labelled;
  // Each true object must map to exactly one of our ids over the whole sequence (no identity
  // switch), and no id may cover two objects.
  std::map<int32_t, std::set<uint32_t>> objects_of_id;
  uint64_t agreeing = 0;
  for (const auto& [key, n] : pairs) {
    objects_of_id[key.first].insert(key.second);
    if (key.first != 0) agreeing += n;
  }
  for (const auto& [object, ids] : ids_of_object)
    EXPECT_EQ(ids.size(), 1u) << "true object " << object << " got " << ids.size() << " ids (identity switch)";
  for (const auto& [id, objects] : objects_of_id)
    EXPECT_EQ(objects.size(), 1u) << "our id " << id << " covers " << objects.size() << " true objects";
  EXPECT_GE(static_cast<double>(agreeing) / thing_pixels, 0.999);
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
