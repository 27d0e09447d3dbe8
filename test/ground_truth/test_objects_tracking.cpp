#include "viper/ground_truth/assignment.h"
#include "viper/ground_truth/label_table.h"
#include "viper/ground_truth/objects.h"
#include "viper/ground_truth/tracking.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <random>

namespace viper {
namespace {

constexpr uint8_t kRoad = 3, kPerson = 20, kCar = 24, kBus = 26;

GlMatrix translation(float x, float y, float z) {
  GlMatrix m = GlMatrix::Identity();
  m(0, 3) = x, m(1, 3) = y, m(2, 3) = z;
  return m;
}

DrawRecord draw(uint32_t index, uint64_t mesh, const GlMatrix& world, uint32_t pixels = 10) {
  DrawRecord d;
  d.index = index;
  d.mesh_key = mesh;
  d.matrix_flags = kHasWorld | kHasView | kHasProjection;
  d.world = world;
  d.visible_pixels = pixels;
  return d;
}

std::vector<bool> thingMask() {
  std::vector<bool> m(32, false);
  for (int c : {13, 16, 17, 19, 20, 23, 24, 25, 26, 27}) m[c] = true;
  return m;
}

// A bus whose wheel mesh is shared with cars (labelled car), and a car with the same wheel mesh.
struct Scene {
  LabelTable labels;
  CaptureFrame frame;
  Scene() {
    labels.setMesh(0xB0, kBus);     // bus body
    labels.setMesh(0xB1, kBus);     // bus windows
    labels.setMesh(0xA1, kCar);     // wheel, annotated once as "car"
    labels.setMesh(0xC0, kCar);     // car body
    labels.setMesh(0xB2, kBus);     // bus lights
    labels.setMesh(0x60, kRoad);    // road
    labels.setMesh(0x61, 9);        // building (also placed with identity)
    const GlMatrix bus = translation(10, 0, 0), car = translation(-5, 2, 0);
    frame.width = 4, frame.height = 2;
    frame.draws = {draw(0, 0x60, GlMatrix::Identity()), draw(1, 0xB0, bus), draw(2, 0xA1, bus),
                   draw(3, 0xA1, bus),     draw(4, 0xB1, bus),    draw(5, 0xC0, car),
                   draw(6, 0xA1, car),     draw(7, 0x61, GlMatrix::Identity()), draw(8, 0xB2, bus, 0)};
    frame.draw_ids = {1, 2, 3, 0, 6, 7, 8, 3};
  }
};

TEST(Objects, SharedWorldMatrixFormsOneObjectAndTheVoteOverridesSharedParts) {
  Scene s;
  const auto objects = groupObjects(s.frame, s.labels, thingMask());
  ASSERT_EQ(objects.size(), 3u);  // static (identity), bus, car
  EXPECT_EQ(objects[1].draws, (std::vector<uint32_t>{1, 2, 3, 4, 8}));
  EXPECT_EQ(objects[1].class_id, kBus);  // 3 bus parts outvote 2 wheels labelled car
  EXPECT_TRUE(objects[1].is_thing);
  EXPECT_EQ(objects[2].class_id, kCar);
  EXPECT_FALSE(objects[0].is_thing);

  const DrawAssignment a = assignDraws(s.frame, s.labels, objects);
  EXPECT_EQ(a.draw_class[2], kBus) << "a shared wheel takes the class of its vehicle";
  EXPECT_EQ(a.draw_class[6], kCar);
  EXPECT_EQ(a.draw_class[0], kRoad) << "stuff keeps its own label";
  EXPECT_EQ(a.draw_class[7], 9);

  DrawRuns runs;
  findDrawRuns(s.frame, runs);
  std::vector<uint8_t> sem(8);
  renderSemantic(runs, a, sem.data());
  EXPECT_EQ(sem, (std::vector<uint8_t>{kRoad, kBus, kBus, 0, kCar, kCar, 9, kBus}));
  std::vector<int32_t> inst(8);
  renderInstances(runs, instanceOfDraws(a, {0, 5, 7}), inst.data());
  EXPECT_EQ(inst, (std::vector<int32_t>{0, 5, 5, 0, 7, 7, 0, 5}));
  std::vector<uint8_t> edges(8);
  renderBoundariesOfRuns(runs, instanceOfDraws(a, {0, 5, 7}), edges.data());
  EXPECT_EQ(edges, (std::vector<uint8_t>{255, 255, 255, 255, 255, 255, 255, 255}));

  auto objs = objects;
  measureObjects(runs, a, objs);
  EXPECT_EQ(objs[1].pixel_count, 3u);
  EXPECT_EQ(objs[1].x_min, 1);
  EXPECT_EQ(objs[1].x_max, 3);
  EXPECT_EQ(objs[1].y_min, 0);
  EXPECT_EQ(objs[1].y_max, 1);
}

// A w x h frame of 12 draws (every `road_every`-th labelled road, the others car) whose draw ids
// are random runs of 1..max_run pixels, ids past the draw list and id 0 among them; its objects,
// their draws' assignment and object ids from 40.
struct RandomRunsFrame {
  static constexpr uint32_t kDraws = 12;
  CaptureFrame f;
  std::vector<FrameObject> objects;
  DrawAssignment a;
  std::vector<int32_t> object_ids;
  RandomRunsFrame(uint32_t w, uint32_t h, size_t max_run, uint32_t road_every, std::mt19937& rng) {
    f.width = w, f.height = h;
    for (uint32_t i = 0; i < kDraws; ++i) f.draws.push_back(draw(i, 100 + i, translation(float(i % 4), 0, 0)));
    while (f.draw_ids.size() < f.pixelCount()) {
      const uint32_t id = std::uniform_int_distribution<uint32_t>(0, kDraws + 2)(rng);
      const size_t length = std::uniform_int_distribution<size_t>(1, max_run)(rng);
      f.draw_ids.insert(f.draw_ids.end(), std::min(length, f.pixelCount() - f.draw_ids.size()), id);
    }
    LabelTable labels;
    for (uint32_t i = 0; i < kDraws; ++i) labels.setMesh(100 + i, i % road_every ? kCar : kRoad);
    objects = groupObjects(f, labels, thingMask());
    a = assignDraws(f, labels, objects);
    object_ids.resize(objects.size());
    std::iota(object_ids.begin(), object_ids.end(), 40);
  }
};

// The run-based kernels against the per-pixel definition, on rows whose width is no multiple of
// the four ids compared at once, with runs of 1..37 pixels, ids past the draw list and id 0.
TEST(Objects, DrawRunsGiveThePerPixelImagesAndMeasures) {
  std::mt19937 rng(7);
  const RandomRunsFrame r(67, 9, 37, 2, rng);
  const CaptureFrame& f = r.f;
  const auto& objects = r.objects;
  const DrawAssignment& a = r.a;
  const std::vector<int32_t>& object_ids = r.object_ids;
  constexpr uint32_t kDraws = RandomRunsFrame::kDraws;

  DrawRuns runs;
  findDrawRuns(f, runs);
  size_t next = 0;
  for (const DrawRuns::Run& r : runs.runs) {
    ASSERT_EQ(r.start, next) << "runs cover every pixel in order";
    ASSERT_GT(r.length, 0u);
    ASSERT_EQ(r.start / f.width, (r.start + r.length - 1) / f.width) << "a run stays in its row";
    for (uint32_t i = r.start; i < r.start + r.length; ++i) ASSERT_EQ(f.draw_ids[i], r.id) << "pixel " << i;
    const uint32_t end = r.start + r.length;
    if (end % f.width != 0) {
      ASSERT_NE(f.draw_ids[end], r.id) << "a run ends where the id changes, pixel " << end;
    }
    next = end;
  }
  ASSERT_EQ(next, f.pixelCount());

  std::vector<uint8_t> sem(f.pixelCount(), 99);
  std::vector<int32_t> inst(f.pixelCount(), -7);
  renderSemantic(runs, a, sem.data());
  renderInstances(runs, instanceOfDraws(a, object_ids), inst.data());
  auto measured = objects;
  measureObjects(runs, a, measured);
  std::vector<uint32_t> count(objects.size(), 0);
  std::vector<int> x_min(objects.size(), 1 << 20), x_max(objects.size(), -1), y_min = x_min, y_max = x_max;
  for (size_t i = 0; i < f.pixelCount(); ++i) {
    const uint32_t id = f.draw_ids[i];
    const bool drawn = id != 0 && id <= kDraws;
    const int32_t k = drawn ? a.draw_object[id - 1] : -1;
    EXPECT_EQ(sem[i], drawn ? a.draw_class[id - 1] : 0) << "pixel " << i;
    EXPECT_EQ(inst[i], k >= 0 ? object_ids[k] : 0) << "pixel " << i;
    if (k < 0) continue;
    ++count[k];
    const int x = static_cast<int>(i % f.width), y = static_cast<int>(i / f.width);
    x_min[k] = std::min(x_min[k], x), x_max[k] = std::max(x_max[k], x);
    y_min[k] = std::min(y_min[k], y), y_max[k] = std::max(y_max[k], y);
  }
  for (size_t k = 0; k < objects.size(); ++k) {
    EXPECT_EQ(measured[k].pixel_count, count[k]) << "object " << k;
    if (count[k] == 0) continue;
    EXPECT_EQ(measured[k].x_min, x_min[k]) << "object " << k;
    EXPECT_EQ(measured[k].x_max, x_max[k]) << "object " << k;
    EXPECT_EQ(measured[k].y_min, y_min[k]) << "object " << k;
    EXPECT_EQ(measured[k].y_max, y_max[k]) << "object " << k;
  }
}

// The boundaries' definition on an instance image: 255 where a 4-neighbour inside the image has
// another id.
std::vector<uint8_t> boundariesOf(const std::vector<int32_t>& ids, int w, int h) {
  std::vector<uint8_t> out(ids.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int32_t v = ids[static_cast<size_t>(y) * w + x];
      for (const auto& [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        const int nx = x + dx, ny = y + dy;
        if (nx >= 0 && nx < w && ny >= 0 && ny < h && ids[static_cast<size_t>(ny) * w + nx] != v)
          out[static_cast<size_t>(y) * w + x] = 255;
      }
    }
  return out;
}

// Boundaries from the runs of draws are those of the instance image (boundariesOf): random runs of
// 1 to 40 pixels (draws of one object and stuff side by side, ids past the list, id 0), rows and
// columns of one pixel.
TEST(Objects, BoundariesOfRunsAreThoseOfTheInstanceImage) {
  std::mt19937 rng(3);
  const std::vector<std::pair<uint32_t, uint32_t>> sizes = {{67, 9}, {203, 7}, {1, 5}, {5, 1}, {1, 1}, {2, 2}};
  for (const auto& [w, h] : sizes) {
    const RandomRunsFrame r(w, h, 40, 3, rng);
    const CaptureFrame& f = r.f;
    DrawRuns runs;
    findDrawRuns(f, runs);
    std::vector<int32_t> inst(f.pixelCount());
    renderInstances(runs, instanceOfDraws(r.a, r.object_ids), inst.data());
    const std::vector<uint8_t> want = boundariesOf(inst, static_cast<int>(w), static_cast<int>(h));
    std::vector<uint8_t> got(f.pixelCount(), 7);
    renderBoundariesOfRuns(runs, instanceOfDraws(r.a, r.object_ids), got.data());
    EXPECT_EQ(got, want) << w << "x" << h;
    if (w * h > 100) {
      EXPECT_GT(std::count(want.begin(), want.end(), 0), 0);
      EXPECT_GT(std::count(want.begin(), want.end(), 255), 0);
    }
  }
}

TEST(Objects, VoteTieGoesToTheClassWithMorePixels) {
  LabelTable labels;
  labels.setMesh(1, kBus);
  labels.setMesh(2, kCar);
  CaptureFrame f;
  f.draws = {draw(0, 1, translation(1, 0, 0), 50), draw(1, 2, translation(1, 0, 0), 10),
             draw(2, 99, translation(1, 0, 0), 500)};  // unlabelled part does not vote
  const auto objects = groupObjects(f, labels, thingMask());
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].class_id, kBus);
}

TEST(Objects, WeightedVoteLetsALargeBodyOutvoteManyWheels) {
  LabelTable labels;
  labels.setMesh(0xB0, kBus);
  labels.setMesh(0xA1, kCar);
  CaptureFrame f;
  const GlMatrix bus = translation(3, 0, 0);
  f.draws = {draw(0, 0xB0, bus)};
  for (uint32_t i = 1; i <= 6; ++i) f.draws.push_back(draw(i, 0xA1, bus));
  EXPECT_EQ(groupObjects(f, labels, thingMask())[0].class_id, kCar) << "plain majority: six wheels win";
  const VoteWeight area = [](const DrawRecord& d) { return d.mesh_key == 0xB0 ? 60.0 : 1.5; };
  EXPECT_EQ(groupObjects(f, labels, thingMask(), area)[0].class_id, kBus);
}

TEST(LabelTable, SaveLoadRoundTripAndErrors) {
  LabelTable t;
  t.setMesh(0x8f3a0c1d22e4b7a9ull, kCar);
  t.setTexture(0x1ull, 9);
  t.setProgram(0xffffffffffffffffull, 2);
  const std::string path = ::testing::TempDir() + "labels_roundtrip.yaml";
  t.save(path);
  const LabelTable u = LabelTable::load(path);
  DrawRecord d;
  d.mesh_key = 0x8f3a0c1d22e4b7a9ull;
  EXPECT_EQ(u.classOf(d), kCar);
  d.mesh_key = 5;
  d.texture_keys = {7, 1};
  EXPECT_EQ(u.classOf(d), 9);
  d.texture_keys.clear();
  d.program_key = 0xffffffffffffffffull;
  EXPECT_EQ(u.classOf(d), 2);
  EXPECT_EQ(u.size(), 3u);

  const std::string bad = ::testing::TempDir() + "labels_bad.yaml";
  std::FILE* f = std::fopen(bad.c_str(), "w");
  std::fputs("meshes:\n  \"12ab\": 3\n", f);
  std::fclose(f);
  try {
    LabelTable::load(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("labels_bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("12ab"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LabelTable::load(::testing::TempDir() + "missing.yaml"), std::runtime_error);
}

TEST(Assignment, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 5, m = n + trial % 3;
    Eigen::MatrixXd c(n, m);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < m; ++j) c(i, j) = u(rng);
    const auto a = solveAssignment(c);
    double got = 0.0;
    for (int i = 0; i < n; ++i) got += c(i, a[i]);
    std::vector<int> perm(m);
    std::iota(perm.begin(), perm.end(), 0);
    double best = 1e18;
    do {
      double s = 0.0;
      for (int i = 0; i < n; ++i) s += c(i, perm[i]);
      best = std::min(best, s);
    } while (std::next_permutation(perm.begin(), perm.end()));
    EXPECT_NEAR(got, best, 1e-9) << "trial " << trial;
  }
  EXPECT_THROW(solveAssignment(Eigen::MatrixXd::Zero(3, 2)), std::invalid_argument);
}

FrameObject thing(uint8_t cls, std::vector<uint64_t> meshes) {
  FrameObject o;
  o.class_id = cls;
  o.is_thing = true;
  o.mesh_keys = std::move(meshes);
  return o;
}

TEST(Tracker, CrossingCarsKeepTheirIdsByLeastTotalMotion) {
  Tracker tracker;
  const double dt = 1.0 / 15;
  std::vector<int32_t> first;
  for (int f = 0; f < 30; ++f) {
    // Two identical cars driving towards each other on parallel lanes 3 m apart at 10 m/s.
    const double x = 10.0 * f * dt;
    const auto ids = tracker.update(f * dt, {thing(kCar, {1}), thing(kCar, {1})},
                                    {Eigen::Vector3d(x - 15, 0, 0), Eigen::Vector3d(15 - x, 3, 0)});
    if (f == 0) first = ids;
    ASSERT_EQ(ids, first) << "frame " << f;
  }
}

TEST(Tracker, HiddenObjectKeepsItsIdWithinTheWindowAndLosesItAfter) {
  TrackerOptions opt;
  opt.extrapolate_frames = 5;
  Tracker tracker(opt);
  const double dt = 0.1;
  int32_t id = 0;
  int f = 0;
  for (; f < 5; ++f) id = tracker.update(f * dt, {thing(kPerson, {2})}, {Eigen::Vector3d(f * 0.15, 0, 0)})[0];
  for (; f < 9; ++f) tracker.update(f * dt, {}, {});  // hidden 4 frames, walking on
  EXPECT_EQ(tracker.update(f * dt, {thing(kPerson, {2})}, {Eigen::Vector3d(f * 0.15, 0, 0)})[0], id);
  ++f;
  for (int k = 0; k < 7; ++k, ++f) tracker.update(f * dt, {}, {});  // hidden longer than the window
  EXPECT_NE(tracker.update(f * dt, {thing(kPerson, {2})}, {Eigen::Vector3d(f * 0.15, 0, 0)})[0], id);
}

TEST(Tracker, ResumingByResourcesGivesAKartBackItsIdAfterAnyGap) {
  TrackerOptions opt;
  opt.extrapolate_frames = 5;
  opt.resume_by_resources = true;
  Tracker tracker(opt);
  const double dt = 0.1;
  // Two karts of their own models (bodies 1 and 2) sharing a wheel mesh (9).
  auto karts = [&](double t, bool first, bool second) {
    std::vector<FrameObject> o;
    std::vector<Eigen::Vector3d> p;
    if (first) o.push_back(thing(kCar, {1, 9})), p.emplace_back(t * 10, 0, 0);
    if (second) o.push_back(thing(kCar, {2, 9})), p.emplace_back(t * 10, 5, 0);
    return tracker.update(t, o, p);
  };
  const auto ids = karts(0, true, true);
  int f = 1;
  for (; f < 20; ++f) karts(f * dt, false, true);  // the first kart out of sight for 19 frames
  EXPECT_EQ(karts(f * dt, true, true), ids) << "back with its own id";
  ++f;
  // Only the shared wheel comes back (its body not drawn): it could be either kart, so a new id.
  for (int k = 0; k < 8; ++k, ++f) karts(f * dt, false, true);
  const int32_t wheel = tracker.update(f * dt, {thing(kCar, {9}), thing(kCar, {2, 9})},
                                       {Eigen::Vector3d(f * dt * 10, 0, 0), Eigen::Vector3d(f * dt * 10, 5, 0)})[0];
  EXPECT_NE(wheel, ids[0]);
  // Off (the default): a long gap means a new id.
  Tracker plain;
  const int32_t id = plain.update(0, {thing(kCar, {1})}, {Eigen::Vector3d::Zero()})[0];
  for (int k = 1; k < 20; ++k) plain.update(k * dt, {}, {});
  EXPECT_NE(plain.update(2.0, {thing(kCar, {1})}, {Eigen::Vector3d::Zero()})[0], id);
}

TEST(Tracker, LevelOfDetailSwapKeepsTheId) {
  Tracker tracker;
  const double dt = 1.0 / 15;
  int32_t id = tracker.update(0, {thing(kCar, {10, 11})}, {Eigen::Vector3d(0, 0, 0)})[0];
  EXPECT_EQ(tracker.update(dt, {thing(kCar, {10, 11})}, {Eigen::Vector3d(1, 0, 0)})[0], id);
  // Every mesh swapped for a lower level of detail, motion continuous.
  EXPECT_EQ(tracker.update(2 * dt, {thing(kCar, {20, 21})}, {Eigen::Vector3d(2, 0, 0)})[0], id);
  EXPECT_EQ(tracker.update(3 * dt, {thing(kCar, {10, 11})}, {Eigen::Vector3d(3, 0, 0)})[0], id);
}

TEST(Tracker, ClassSpeedAndResourceForbidEdges) {
  Tracker tracker;
  const int32_t car = tracker.update(0, {thing(kCar, {1})}, {Eigen::Vector3d(0, 0, 0)})[0];
  // Another class at the same place, a car of other resources far from the prediction, and a
  // person "moving" 50 m in 0.1 s are all new tracks; the car moving 3 m is the same car.
  const auto ids = tracker.update(0.1, {thing(kBus, {1}), thing(kCar, {9}), thing(kCar, {1})},
                                  {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 5, 0), Eigen::Vector3d(3, 0, 0)});
  EXPECT_NE(ids[0], car);
  EXPECT_NE(ids[1], car);
  EXPECT_EQ(ids[2], car);
  const int32_t person = tracker.update(0.2, {thing(kPerson, {4})}, {Eigen::Vector3d(0, 0, 0)})[0];
  EXPECT_NE(tracker.update(0.3, {thing(kPerson, {4})}, {Eigen::Vector3d(50, 0, 0)})[0], person);
}

TEST(Tracker, StuffGetsNoIdAndTimeGoingBackResets) {
  Tracker tracker;
  FrameObject road;
  road.class_id = kRoad;
  const auto ids = tracker.update(1.0, {road, thing(kCar, {1})}, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  EXPECT_EQ(ids[0], 0);
  EXPECT_GT(ids[1], 0);
  const auto again = tracker.update(0.5, {thing(kCar, {1})}, {Eigen::Vector3d::Zero()});
  EXPECT_TRUE(tracker.wasReset());
  EXPECT_GT(again[0], ids[1]) << "ids are never reused";
}

}  // namespace
}  // namespace viper
