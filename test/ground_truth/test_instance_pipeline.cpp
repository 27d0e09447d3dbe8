#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/semantic_overlay.h"

#include "../common/vector_paths.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <random>

namespace viper {
namespace {

// Two cars (body + shared wheel) driving right over a road, 3 frames, 8x2 pixels.
struct Sequence {
  LabelTable labels;
  std::vector<CaptureFrame> frames;
  Sequence() {
    labels.setMesh(10, 24);  // car body
    labels.setMesh(11, 24);  // wheel
    labels.setMesh(1, 3);    // road
    for (int f = 0; f < 3; ++f) {
      CaptureFrame fr;
      fr.number = f, fr.time_s = f / 15.0, fr.width = 8, fr.height = 2;
      auto draw = [&](uint64_t mesh, float x) {
        DrawRecord d;
        d.index = static_cast<uint32_t>(fr.draws.size());
        d.mesh_key = mesh;
        d.matrix_flags = kHasWorld;
        d.world(0, 3) = x;
        fr.draws.push_back(d);
      };
      draw(1, 0);                  // road, identity
      draw(10, 5 + 0.5f * f);      // car A
      draw(11, 5 + 0.5f * f);
      draw(10, 20 + 0.5f * f);     // car B
      draw(11, 20 + 0.5f * f);
      fr.draw_ids = {1, 2, 2, 3, 1, 4, 5, 1, 1, 1, 1, 1, 1, 4, 4, 1};
      if (f == 0) {
        MeshRecord m;
        m.key = 10;
        m.positions_xyz = {0, 0, 0, 4, 0, 0, 0, 2, 0, 0, 0, 1.5f};
        m.indices = {0, 1, 2, 0, 1, 3};
        fr.new_meshes = {m};
      }
      frames.push_back(fr);
    }
  }
};

TEST(InstancePipeline, StableIdsClassesImagesAndBoxes) {
  Sequence s;
  InstancePipeline pipeline(s.labels);
  std::vector<int32_t> first_ids;
  for (const CaptureFrame& f : s.frames) {
    const InstanceFrame out = pipeline.process(f);
    ASSERT_EQ(out.objects.size(), 3u);
    EXPECT_EQ(out.objects[0].track_id, 0) << "road is stuff";
    const int32_t a = out.objects[1].track_id, b = out.objects[2].track_id;
    EXPECT_GT(a, 0);
    EXPECT_GT(b, 0);
    EXPECT_NE(a, b);
    if (first_ids.empty()) first_ids = {a, b};
    EXPECT_EQ(first_ids, (std::vector<int32_t>{a, b})) << "frame " << f.number;
    EXPECT_EQ(out.semantic, (std::vector<uint8_t>{3, 24, 24, 24, 3, 24, 24, 3, 3, 3, 3, 3, 3, 24, 24, 3}));
    EXPECT_EQ(out.instance_ids[1], a);
    EXPECT_EQ(out.instance_ids[5], b);
    EXPECT_EQ(out.instance_ids[0], 0);
    EXPECT_EQ(out.objects[2].object.pixel_count, 4u);
    EXPECT_EQ(out.objects[1].box_status, BoxStatus::kOk);
    EXPECT_NEAR(out.objects[1].box.center.x(), 7 + 0.5 * f.number, 1e-6);
    // Car B's body arrived in frame 0, the wheel mesh never did: its box is the body's.
    EXPECT_TRUE(out.objects[2].box.size.isApprox(Eigen::Vector3d(4, 2, 1.5)));
  }
  std::vector<uint8_t> rgb(3 * 2);
  const uint8_t cls[2] = {24, 3};
  const int32_t ids[2] = {258, 0};
  encodeViperInstances(cls, ids, 2, rgb.data());
  EXPECT_EQ(rgb, (std::vector<uint8_t>{24, 1, 2, 3, 0, 0}));
}

// VIPER's instance picture on every path: the bytes of one pixel at a time, for lengths around the
// vector blocks (32 pixels), ids above 65535 and negative (their low 16 bits).
TEST(InstancePipeline, ViperInstancePictureIsTheSameOnEveryPath) {
  for (size_t n : {0, 1, 31, 32, 33, 64, 100, 1027}) {
    std::vector<uint8_t> cls(n);
    std::vector<int32_t> ids(n);
    for (size_t i = 0; i < n; ++i) {
      cls[i] = static_cast<uint8_t>(i * 37 + 5);
      ids[i] = static_cast<int32_t>(i * 2654435761u);  // large and negative ones too
    }
    std::vector<uint8_t> want(3 * n, 0xee);
    encodeViperInstances(cls.data(), ids.data(), n, want.data(), Instructions::kScalar);
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(want[3 * i], cls[i]);
      ASSERT_EQ(want[3 * i + 1], (static_cast<uint32_t>(ids[i]) >> 8) & 0xff);
      ASSERT_EQ(want[3 * i + 2], static_cast<uint32_t>(ids[i]) & 0xff);
    }
    for (Instructions path : test::vectorPaths()) {
      std::vector<uint8_t> got(3 * n, 0xee);
      encodeViperInstances(cls.data(), ids.data(), n, got.data(), path);
      EXPECT_EQ(got, want) << test::pathName(path) << ", " << n << " pixels";
    }
  }
}

// Class ids, instance ids and boundaries rendered into caller storage (the instances node's
// messages): the same images and objects as in the frame's own vectors, which are left empty.
TEST(InstancePipeline, ImagesIntoCallerStorageAreTheSame) {
  Sequence s;
  InstancePipeline own(s.labels), caller(s.labels);
  for (const CaptureFrame& f : s.frames) {
    const InstanceFrame expected = own.process(f);
    std::vector<int32_t> ids(f.pixelCount(), -7);
    std::vector<uint8_t> boundaries(f.pixelCount(), 7), semantic(f.pixelCount(), 7);
    InstanceImagesInto into;
    into.instance_ids = ids.data();
    into.boundaries = boundaries.data();
    into.semantic = semantic.data();
    InstanceFrame got;
    caller.process(f, got, into);
    EXPECT_EQ(ids, expected.instance_ids);
    EXPECT_EQ(boundaries, expected.boundaries);
    EXPECT_EQ(semantic, expected.semantic);
    EXPECT_TRUE(got.instance_ids.empty());
    EXPECT_TRUE(got.boundaries.empty());
    EXPECT_TRUE(got.semantic.empty());
    ASSERT_EQ(got.objects.size(), expected.objects.size());
    for (size_t k = 0; k < got.objects.size(); ++k) EXPECT_EQ(got.objects[k].track_id, expected.objects[k].track_id);
  }
}

// Draw ids read from caller storage (a message's pixels) with none in the frame: the same images.
TEST(InstancePipeline, DrawIdsFromCallerStorageGiveTheSameImages) {
  Sequence s;
  InstancePipeline own(s.labels), caller(s.labels);
  for (const CaptureFrame& f : s.frames) {
    const InstanceFrame expected = own.process(f);
    CaptureFrame without_ids = f;
    without_ids.draw_ids.clear();
    InstanceImagesInto into;
    into.draw_ids = f.draw_ids.data();
    InstanceFrame got;
    caller.process(without_ids, got, into);
    EXPECT_EQ(got.semantic, expected.semantic);
    EXPECT_EQ(got.instance_ids, expected.instance_ids);
    EXPECT_EQ(got.boundaries, expected.boundaries);
    ASSERT_EQ(got.objects.size(), expected.objects.size());
    for (size_t k = 0; k < got.objects.size(); ++k) EXPECT_EQ(got.objects[k].track_id, expected.objects[k].track_id);
  }
}

// semantic_color and instances_viper rendered from the runs of draws are colorizeClasses() and
// encodeViperInstances() of the class and instance images: runs of 1 pixel to a whole row, id 0,
// ids past the draw list, classes past the class table (black), cars tracked over frames.
TEST(InstancePipeline, PicturesFromRunsAreThoseOfTheImages) {
  const std::string csv = testing::TempDir() + "viper_ten_classes.csv";
  {
    std::ofstream out(csv);
    out << "id,classname,red,green,blue,class_eval,trainid,instance_eval\n";
    for (int c = 0; c < 10; ++c) out << c << ",c" << c << "," << 20 * c << "," << 255 - c << "," << 7 * c << ",1,0,0\n";
  }
  const ClassTable classes = ClassTable::load(csv);
  std::remove(csv.c_str());
  LabelTable labels;
  labels.setMesh(1, 3);    // road: in the table
  labels.setMesh(10, 24);  // car: a thing past the table (black)
  labels.setMesh(11, 24);
  labels.setMesh(12, 7);
  InstancePipeline own(labels), caller(labels);
  std::mt19937 random(5);
  for (int f = 0; f < 4; ++f) {
    CaptureFrame fr;
    fr.number = f, fr.time_s = f / 15.0, fr.width = 203, fr.height = 9;
    for (uint64_t mesh : {1, 10, 11, 10, 11, 12, 13}) {
      DrawRecord d;
      d.index = static_cast<uint32_t>(fr.draws.size());
      d.mesh_key = mesh;
      d.matrix_flags = kHasWorld;
      d.world(0, 3) = static_cast<float>(d.index / 2 * 10 + f);
      fr.draws.push_back(d);
    }
    const uint32_t longest = f < 2 ? 70 : 400;  // runs of up to 203 pixels: a whole row
    while (fr.draw_ids.size() < fr.pixelCount()) {
      const uint32_t id = random() % 10;  // 0, the 7 draws, and 2 past them
      fr.draw_ids.insert(fr.draw_ids.end(), 1 + random() % longest, id);
    }
    fr.draw_ids.resize(fr.pixelCount());
    const InstanceFrame expected = own.process(fr);
    const size_t n = fr.pixelCount();
    ASSERT_NE(std::count_if(expected.instance_ids.begin(), expected.instance_ids.end(), [](int32_t i) { return i > 0; }),
              0);
    std::vector<uint8_t> color(3 * n), viper(3 * n);
    colorizeClasses(expected.semantic.data(), n, classes, color.data());
    encodeViperInstances(expected.semantic.data(), expected.instance_ids.data(), n, viper.data());
    std::vector<uint8_t> got_color(3 * n, 0xee), got_viper(3 * n, 0xee);
    InstanceImagesInto into;
    into.semantic_color = got_color.data();
    into.classes = &classes;
    into.instances_viper = got_viper.data();
    InstanceFrame got;
    caller.process(fr, got, into);
    EXPECT_EQ(got_color, color) << "frame " << f;
    EXPECT_EQ(got_viper, viper) << "frame " << f;
    EXPECT_EQ(got.instance_ids, expected.instance_ids);
  }
  CaptureFrame fr;
  InstanceImagesInto without_classes;
  std::vector<uint8_t> unused(3);
  without_classes.semantic_color = unused.data();
  InstanceFrame got;
  EXPECT_THROW(caller.process(fr, got, without_classes), std::invalid_argument);
}

TEST(InstancePipeline, InconsistentFramesAreRejectedWithoutSideEffects) {
  Sequence s;
  InstancePipeline pipeline(s.labels);
  CaptureFrame bad = s.frames[0];
  bad.draw_ids.pop_back();
  try {
    pipeline.process(bad);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("draw id image has 15 pixels"), std::string::npos) << e.what();
  }
  EXPECT_EQ(pipeline.meshes().size(), 0u);
  CaptureFrame shuffled = s.frames[0];
  std::swap(shuffled.draws[1], shuffled.draws[2]);
  EXPECT_THROW(pipeline.process(shuffled), std::invalid_argument);
  CaptureFrame nan_world = s.frames[0];
  nan_world.draws[3].world(0, 0) = std::numeric_limits<float>::quiet_NaN();
  nan_world.draws[4].world(0, 0) = std::numeric_limits<float>::quiet_NaN();
  const InstanceFrame out = pipeline.process(nan_world);
  EXPECT_EQ(out.objects.size(), 2u);
  ASSERT_EQ(out.problems.size(), 1u);
  EXPECT_NE(out.problems[0].find("non-finite world matrix"), std::string::npos);
  EXPECT_EQ(out.instance_ids[5], 0) << "pixels of a skipped object have no instance";
}

}  // namespace
}  // namespace viper
