// Amodal masks: the rasteriser's rules on small cases, the step's handling of bad input, and the
// invariants on a real capture of the world (90 frames of traffic, 480x270): every pixel the
// instance image gives an object lies in its amodal mask, the fractions are fractions.
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/amodal.h"
#include "world_pipeline.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/label_table.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace viper {
namespace {

// Clip coordinates of window pixel position (x right, y down from the top edge) of a w x h image,
// at clip w `cw`.
Eigen::Vector4f clipAt(double x, double y, uint32_t w, uint32_t h, float cw = 1.0f) {
  return Eigen::Vector4f(static_cast<float>((2.0 * x / w - 1.0) * cw), static_cast<float>((1.0 - 2.0 * y / h) * cw),
                         0.0f, cw);
}

TEST(TriangleRasterizer, PixelAlignedRectangleCoversItsPixelsOnceEach) {
  TriangleRasterizer r(16, 12);
  // [2, 7) x [1, 5): 5 x 4 pixel centres inside, split along a diagonal through centres' corners.
  const auto a = clipAt(2, 1, 16, 12), b = clipAt(7, 1, 16, 12), c = clipAt(7, 5, 16, 12), d = clipAt(2, 5, 16, 12);
  r.drawClip(a, b, c);
  const uint64_t first = r.coveredPixels();
  r.drawClip(a, c, d);
  EXPECT_EQ(r.coveredPixels(), 20u);
  EXPECT_EQ(r.box().x_min, 2);
  EXPECT_EQ(r.box().x_max, 6);
  EXPECT_EQ(r.box().y_min, 1);
  EXPECT_EQ(r.box().y_max, 4);
  // The two halves share no pixel: drawn apart, their counts add up to the rectangle's.
  TriangleRasterizer s(16, 12);
  s.drawClip(a, c, d);
  EXPECT_EQ(first + s.coveredPixels(), 20u);
}

TEST(TriangleRasterizer, CentreOnAnEdgeGoesToTheLeftAndBottomEdgesOwner) {
  // A rectangle whose edges run through pixel centres: x from 2.5 to 6.5, y from 1.5 to 4.5 (down).
  // GL's bottom-left rule (y up): centres on the left edge (x = 2.5) and on the bottom edge (GL's
  // bottom: image y = 4.5) are in, those on the right (x = 6.5) and top (y = 1.5) are not.
  TriangleRasterizer r(16, 12);
  const auto a = clipAt(2.5, 1.5, 16, 12), b = clipAt(6.5, 1.5, 16, 12), c = clipAt(6.5, 4.5, 16, 12),
             d = clipAt(2.5, 4.5, 16, 12);
  r.drawClip(a, b, c);
  r.drawClip(a, c, d);
  EXPECT_EQ(r.box().x_min, 2);
  EXPECT_EQ(r.box().x_max, 5);
  EXPECT_EQ(r.box().y_min, 2);
  EXPECT_EQ(r.box().y_max, 4);
  EXPECT_EQ(r.coveredPixels(), 12u);
}

TEST(TriangleRasterizer, TriangleThroughTheCameraPlaneIsClippedAtTheNearPlane) {
  // A ground-like triangle with one vertex behind the camera (w < 0): without clipping its
  // projection would flip; clipped, it covers a region near the bottom of the image only.
  const uint32_t w = 64, h = 48;
  TriangleRasterizer r(w, h);
  // Clip space of a perspective camera (near 0.1): z = (f+n)/(n-f) ze + 2fn/(n-f) ze..., w = -ze.
  auto clip = [](double x, double y, double ze) {
    const double n = 0.1, f = 100.0;
    return Eigen::Vector4f(static_cast<float>(x), static_cast<float>(y),
                           static_cast<float>((f + n) / (n - f) * ze + 2 * f * n / (n - f)), static_cast<float>(-ze));
  };
  r.drawClip(clip(-1, -1, -5), clip(1, -1, -5), clip(0, -1, 2));  // y = -1: below the camera
  EXPECT_GT(r.coveredPixels(), 0u);
  EXPECT_GE(r.box().y_min, h / 2);  // below the horizon only
  EXPECT_EQ(r.box().y_max, static_cast<int>(h) - 1);
  EXPECT_FALSE(r.extent().empty);
  EXPECT_GT(r.extent().y_max, h);  // the near-clipped edge lies far below the image
  // Wholly behind the camera: nothing.
  TriangleRasterizer behind(w, h);
  behind.drawClip(clip(-1, -1, 5), clip(1, -1, 5), clip(0, 1, 2));
  EXPECT_EQ(behind.coveredPixels(), 0u);
  EXPECT_TRUE(behind.extent().empty);
}

TEST(KittiLevels, ThresholdsAsDocumented) {
  const AmodalOptions o;
  EXPECT_EQ(occlusionLevel(1.0, 10, o), OcclusionLevel::kFullyVisible);
  EXPECT_EQ(occlusionLevel(0.99, 10, o), OcclusionLevel::kFullyVisible);
  EXPECT_EQ(occlusionLevel(0.98, 10, o), OcclusionLevel::kPartlyOccluded);
  EXPECT_EQ(occlusionLevel(0.5, 10, o), OcclusionLevel::kPartlyOccluded);
  EXPECT_EQ(occlusionLevel(0.49, 10, o), OcclusionLevel::kLargelyOccluded);
  EXPECT_EQ(occlusionLevel(0.0, 10, o), OcclusionLevel::kLargelyOccluded);
  EXPECT_EQ(occlusionLevel(0.0, 0, o), OcclusionLevel::kUnknown);
  EXPECT_EQ(kittiDifficulty(40, OcclusionLevel::kFullyVisible, 0.15), Difficulty::kEasy);
  EXPECT_EQ(kittiDifficulty(39, OcclusionLevel::kFullyVisible, 0.0), Difficulty::kModerate);
  EXPECT_EQ(kittiDifficulty(40, OcclusionLevel::kFullyVisible, 0.16), Difficulty::kModerate);
  EXPECT_EQ(kittiDifficulty(25, OcclusionLevel::kPartlyOccluded, 0.30), Difficulty::kModerate);
  EXPECT_EQ(kittiDifficulty(25, OcclusionLevel::kLargelyOccluded, 0.30), Difficulty::kHard);
  EXPECT_EQ(kittiDifficulty(25, OcclusionLevel::kPartlyOccluded, 0.50), Difficulty::kHard);
  EXPECT_EQ(kittiDifficulty(24, OcclusionLevel::kFullyVisible, 0.0), Difficulty::kIgnored);
  EXPECT_EQ(kittiDifficulty(100, OcclusionLevel::kLargelyOccluded, 0.51), Difficulty::kIgnored);
  EXPECT_EQ(kittiDifficulty(100, OcclusionLevel::kUnknown, 0.0), Difficulty::kIgnored);
}

// A frame of one draw of a unit square mesh seen by an identity camera, and its instance image.
struct SquareFrame {
  CaptureFrame frame;
  MeshRegistry meshes;
  std::vector<TrackedObject> objects;
  std::vector<int32_t> ids;
  SquareFrame() {
    frame.number = 7, frame.width = 8, frame.height = 8;
    MeshRecord m;
    m.key = 42;
    m.positions_xyz = {-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0};
    m.indices = {0, 1, 2, 0, 2, 3};
    meshes.add(m);
    DrawRecord d;
    d.mesh_key = 42;
    d.matrix_flags = kHasWorld | kHasView | kHasProjection;
    frame.draws.push_back(d);
    TrackedObject o;
    o.track_id = 5;
    o.object.draws = {0};
    o.object.class_id = 3;
    objects.push_back(o);
    ids.assign(64, 0);
    for (int y = 2; y < 6; ++y)
      for (int x = 2; x < 6; ++x) ids[y * 8 + x] = 5;
  }
};

TEST(AmodalStep, UnoccludedSquareIsWhollyVisible) {
  SquareFrame s;
  AmodalStep step;
  FrameAmodal out;
  StepProblems problems;
  step.process(s.frame, s.objects, s.ids.data(), s.meshes, out, problems);
  EXPECT_TRUE(problems.empty());
  ASSERT_EQ(out.objects.size(), 1u);
  const AmodalObject& a = out.objects[0];
  EXPECT_EQ(a.track_id, 5);
  EXPECT_EQ(a.amodal_pixels, 16u);
  EXPECT_EQ(a.visible_pixels, 16u);
  EXPECT_EQ(a.visible_outside, 0u);
  EXPECT_DOUBLE_EQ(a.visible_fraction, 1.0);
  EXPECT_DOUBLE_EQ(a.truncation, 0.0);
  EXPECT_EQ(a.box.width(), 4);
  EXPECT_EQ(a.mask.size(), 16u);
  EXPECT_EQ(a.occlusion, OcclusionLevel::kFullyVisible);
  EXPECT_EQ(a.difficulty, Difficulty::kIgnored);  // 4 px high
  // Half hidden by something else in the instance image.
  for (int y = 2; y < 6; ++y) s.ids[y * 8 + 2] = s.ids[y * 8 + 3] = 9;
  step.process(s.frame, s.objects, s.ids.data(), s.meshes, out, problems);
  ASSERT_EQ(out.objects.size(), 1u);
  EXPECT_EQ(out.objects[0].visible_pixels, 8u);
  EXPECT_EQ(out.objects[0].occlusion, OcclusionLevel::kPartlyOccluded);
}

TEST(AmodalStep, TruncationIsTheShareOfTheProjectedBoxOutsideTheImage) {
  SquareFrame s;
  // Moved right by 0.75: ndc x from 0.25 to 1.25, a quarter of it past the image's right edge.
  s.frame.draws[0].world(0, 3) = 0.75f;
  AmodalStep step;
  FrameAmodal out;
  StepProblems problems;
  step.process(s.frame, s.objects, s.ids.data(), s.meshes, out, problems);
  ASSERT_EQ(out.objects.size(), 1u);
  // Window x from (0.25 + 1) * 4 = 5 to (1.25 + 1) * 4 = 9: 1 px of 4 outside.
  EXPECT_NEAR(out.objects[0].truncation, 0.25, 1e-6);
  EXPECT_EQ(out.objects[0].box.x_max, 7);
}

// The problems of the step on `s` (instance ids: `ids`), which must leave the object out.
StepProblems problemsOf(const SquareFrame& s, const int32_t* ids) {
  AmodalStep step;
  FrameAmodal out;
  StepProblems problems;
  step.process(s.frame, s.objects, ids, s.meshes, out, problems);
  EXPECT_TRUE(out.objects.empty());
  return problems;
}

TEST(AmodalStep, BadInputIsNamedAndTheObjectLeftOut) {
  auto expectOne = [](const StepProblems& problems, const std::string& what) {
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_NE(problems[0].text.find(what), std::string::npos) << problems[0].text;
  };
  SquareFrame missing_mesh;
  missing_mesh.frame.draws[0].mesh_key = 43;  // never arrived
  expectOne(problemsOf(missing_mesh, missing_mesh.ids.data()), "track 5: the mesh of draw 0 never arrived");
  SquareFrame short_deformed;
  short_deformed.frame.draws[0].deformed_clip_xyzw.assign(4 * 3, 0.5f);  // 3 vertices for a mesh of 4
  expectOne(problemsOf(short_deformed, short_deformed.ids.data()), "3 deformed vertices for a mesh of 4");
  SquareFrame no_draw;
  no_draw.objects[0].object.draws = {3};
  expectOne(problemsOf(no_draw, no_draw.ids.data()), "names draw 3 but the frame has 1");
  SquareFrame no_projection;
  no_projection.frame.draws[0].matrix_flags = kHasWorld;
  expectOne(problemsOf(no_projection, no_projection.ids.data()), "lacks a finite world, view or projection matrix");
  SquareFrame no_ids;
  const StepProblems problems = problemsOf(no_ids, nullptr);
  expectOne(problems, "no instance ids");
  EXPECT_EQ(problems.at(0).input, StepInput::kDrawIds);
}

#ifdef VIPER_WORLD_CAPTURE
TEST(AmodalOnTheWorld, EveryVisiblePixelIsInTheAmodalMask) {
  CaptureReader reader(VIPER_WORLD_CAPTURE);
  InstancePipeline pipeline = test::worldInstancePipeline(VIPER_WORLD_LABELS, VIPER_CLASSES_CSV);
  AmodalStep step;
  CaptureFrame f;
  size_t frames = 0, objects = 0, whole = 0, occluded = 0, truncated = 0;
  uint64_t visible = 0, amodal = 0, outside = 0;
  size_t levels[4] = {0, 0, 0, 0}, difficulties[4] = {0, 0, 0, 0};
  while (reader.next(f) == CaptureReader::Status::kFrame) {
    const InstanceFrame inst = pipeline.process(f);
    FrameAmodal out;
    StepProblems problems;
    step.process(f, inst.objects, inst.instance_ids.data(), pipeline.meshes(), out, problems);
    for (const StepProblem& p : problems) ADD_FAILURE() << p.text;
    size_t tracked = 0;
    for (const TrackedObject& o : inst.objects) tracked += o.track_id > 0;
    ASSERT_EQ(out.objects.size(), tracked);
    for (size_t k = 0, j = 0; k < inst.objects.size(); ++k) {
      const TrackedObject& o = inst.objects[k];
      if (o.track_id <= 0) continue;
      const AmodalObject& a = out.objects[j++];
      ASSERT_EQ(a.track_id, o.track_id);
      // Every visible pixel is in the mask: checked pixel by pixel here, not through the step's count.
      uint32_t seen = 0, seen_inside = 0;
      for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x)
          if (inst.instance_ids[y * f.width + x] == o.track_id) {
            ++seen;
            if (a.covers(x, y)) ++seen_inside;
          }
      EXPECT_EQ(seen_inside, seen) << "frame " << f.number << " track " << o.track_id;
      EXPECT_EQ(a.visible_pixels, seen_inside);
      EXPECT_EQ(a.visible_outside, seen - seen_inside);
      EXPECT_EQ(seen, o.object.pixel_count);
      EXPECT_GE(a.amodal_pixels, a.visible_pixels);
      EXPECT_GE(a.visible_fraction, 0.0);
      EXPECT_LE(a.visible_fraction, 1.0);
      EXPECT_GE(a.truncation, 0.0);
      EXPECT_LE(a.truncation, 1.0);
      uint32_t ones = 0;
      for (uint8_t m : a.mask) ones += m;
      EXPECT_EQ(ones, a.amodal_pixels);
      ++objects;
      visible += seen_inside, amodal += a.amodal_pixels, outside += seen - seen_inside;
      whole += a.visible_pixels == a.amodal_pixels && a.amodal_pixels > 0;
      occluded += a.visible_pixels < a.amodal_pixels;
      truncated += a.truncation > 0.0;
      ++levels[static_cast<int>(a.occlusion)], ++difficulties[static_cast<int>(a.difficulty)];
    }
    ++frames;
  }
  ASSERT_GT(frames, 0u);
  ASSERT_GT(objects, 0u);
  EXPECT_GT(occluded, 0u);  // the world's traffic occludes itself: the masks are not the visible ones
  std::printf("\nworld: %zu frames, %zu tracked objects: %zu wholly visible, %zu partly occluded, %zu truncated;\n"
              "visible %llu of amodal %llu px; visible px outside the amodal mask: %llu\n"
              "occlusion levels 0/1/2/3: %zu %zu %zu %zu; easy/moderate/hard/ignored: %zu %zu %zu %zu\n",
              frames, objects, whole, occluded, truncated, static_cast<unsigned long long>(visible),
              static_cast<unsigned long long>(amodal), static_cast<unsigned long long>(outside), levels[0], levels[1],
              levels[2], levels[3], difficulties[0], difficulties[1], difficulties[2], difficulties[3]);
}
#endif

}  // namespace
}  // namespace viper
