// The ground-truth steps on core types and GroundTruthPipeline, which runs them all on one decoded
// frame: the pipeline gives what the steps give one by one (as the nodes run them, each with its own
// meshes and its own camera), odometry, tracks, boxes with velocities and flows into the caller's
// storage; frames out of order and frames without draw ids are dropped and named. The modalities
// beyond VIPER's (normals, labelled cloud, amodal masks, scene flow) are the steps' own, and computed
// only when asked for.
#include "viper/ground_truth/ground_truth_pipeline.h"
#include "viper/ground_truth/scene_flow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <vector>

namespace viper {
namespace {

constexpr uint32_t kW = 8, kH = 2;

GlMatrix perspective() {
  const float n = 0.5f, f = 100.0f;
  GlMatrix p = GlMatrix::Zero();
  p(0, 0) = 1.0f, p(1, 1) = 4.0f;
  p(2, 2) = (f + n) / (n - f), p(2, 3) = 2 * f * n / (n - f);
  p(3, 2) = -1.0f;
  return p;
}

// A camera moving along x at 1.5 m/s over a road (stuff) and a car (a thing, its mesh in the store)
// driving along x at 7.5 m/s, 15 frames a second; every surface 10 m away.
struct Sequence {
  LabelTable labels;
  ClassTable classes = ClassTable::load("config/viper_classes.csv");
  MeshRecord car_mesh;
  std::vector<GroundTruthInputPtr> frames;
  std::vector<std::shared_ptr<std::vector<uint32_t>>> ids, primitives;
  std::vector<std::shared_ptr<std::vector<float>>> depth;

  Sequence() {
    labels.setMesh(1, 3);    // road
    labels.setMesh(10, 24);  // car
    car_mesh.key = 10;
    car_mesh.positions_xyz = {-2, -1, 0, 2, -1, 0, 2, 1, 0, -2, 1, 1.5f};
    car_mesh.indices = {0, 1, 2, 0, 2, 3};
    for (int f = 0; f < 4; ++f) frames.push_back(frame(f, f));
  }

  GroundTruthInputPtr frame(int f, uint64_t number, bool with_ids = true) {
    auto in = std::make_shared<GroundTruthInput>();
    in->stamp = FrameStamp{100, static_cast<uint32_t>(f * 66666667u)};
    CaptureFrame& fr = in->frame;
    fr.number = number, fr.time_s = in->stamp.seconds(), fr.width = kW, fr.height = kH;
    GlMatrix view = GlMatrix::Identity();
    view(0, 3) = -0.1f * f;  // the camera moves along +x
    auto draw = [&](uint64_t mesh, float x, uint32_t pixels) {
      DrawRecord d;
      d.index = static_cast<uint32_t>(fr.draws.size());
      d.mesh_key = mesh;
      d.matrix_flags = kHasWorld | kHasView | kHasProjection;
      d.world(0, 3) = x;
      d.world(2, 3) = -10.0f;
      d.view = view;
      d.projection = perspective();
      d.visible_pixels = pixels;
      d.primitive_count = 2;
      fr.draws.push_back(d);
    };
    draw(1, 0, 12);             // road
    draw(10, 3 + 0.5f * f, 4);  // car
    ids.push_back(std::make_shared<std::vector<uint32_t>>(
        std::vector<uint32_t>{1, 1, 2, 2, 1, 1, 1, 1, 1, 1, 2, 2, 1, 1, 1, 1}));
    primitives.push_back(std::make_shared<std::vector<uint32_t>>(std::vector<uint32_t>(kW * kH, 0)));
    depth.push_back(std::make_shared<std::vector<float>>(kW * kH, 10.0f));
    if (with_ids) in->draw_ids = ids.back()->data();
    in->primitive_ids = primitives.back()->data();
    in->depth_m = depth.back()->data();
    return in;
  }
};

// Flows into vectors, by kind, with the stamp of the frame each starts from.
class VectorSink : public FlowSink {
 public:
  struct Flow {
    FrameStamp from;
    std::vector<float> uv;
    std::vector<uint8_t> visible;
  };
  FlowBuffers take(FlowKind kind, const GroundTruthInput& from) override {
    Flow& f = flows[static_cast<int>(kind)];
    f.from = from.stamp;
    const size_t n = from.frame.pixelCount();
    f.uv.assign(2 * n, -12345.0f);  // what the flow must overwrite
    f.visible.assign(n, 77);
    return FlowBuffers{f.uv.data(), f.visible.data()};
  }
  std::map<int, Flow> flows;
};

size_t count(const StepProblems& problems, const char* kind) {
  size_t n = 0;
  for (const StepProblem& p : problems) n += std::string(p.kind) == kind;
  return n;
}

TEST(GroundTruthPipeline, OdometryTracksBoxesAndFlows) {
  Sequence s;
  GroundTruthPipeline pipeline(s.labels, s.classes, GroundTruthSettings());
  pipeline.addMeshes({s.car_mesh});
  GroundTruthResult out;
  int32_t car_track = 0;
  for (size_t i = 0; i < s.frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    VectorSink sink;
    StepProblems problems;
    ASSERT_TRUE(pipeline.process(s.frames[i], InstanceImagesInto(), sink, out, problems));
    EXPECT_EQ(count(problems, "no_box"), 0u);
    ASSERT_TRUE(out.camera);
    ASSERT_TRUE(out.ego);
    EXPECT_NEAR(out.ego->pose.map_from_body.translation().x(), 0.1 * i, 1e-6);
    EXPECT_EQ(out.ego->twist.has_value(), i > 0);
    if (i > 0) EXPECT_NEAR(out.ego->twist->linear_mps.x(), 0.0, 1e-3) << "body x is forward: the camera moves sideways";
    // The instances: the road (stuff) and the car, whose track lasts.
    ASSERT_EQ(out.instances.objects.size(), 2u);
    const TrackedObject& car = out.instances.objects[1];
    EXPECT_GT(car.track_id, 0);
    if (i == 0) car_track = car.track_id;
    EXPECT_EQ(car.track_id, car_track);
    EXPECT_EQ(out.instances.semantic.size(), kW * kH) << "no storage given: the images are the result's";
    EXPECT_EQ(out.instances.semantic[2], 24);
    // Its box, in the map and in the optical frame, with its velocity.
    ASSERT_EQ(out.boxes.boxes.size(), 1u);
    EXPECT_TRUE(out.boxes.has_optical);
    const TrackBox& box = out.boxes.boxes[0];
    EXPECT_EQ(box.track_id, car_track);
    EXPECT_NEAR(box.in_map.center.x(), 3 + 0.5 * i, 1e-5);
    EXPECT_NEAR(box.in_optical.center.z(), 10.0 - 0.75, 1e-4) << "the box's centre, in front of the camera";
    if (i > 0) EXPECT_NEAR(box.velocity_map.x(), 7.5, 1e-3);
    // Flow from the second frame on: forward from the previous frame, backward from this one, every
    // value written into the sink's storage.
    EXPECT_EQ(out.flow.forward, i > 0);
    EXPECT_EQ(out.flow.backward, i > 0);
    EXPECT_FALSE(out.flow.wide);
    if (i > 0) {
      const VectorSink::Flow& fwd = sink.flows.at(static_cast<int>(FlowKind::kForward));
      const VectorSink::Flow& bwd = sink.flows.at(static_cast<int>(FlowKind::kBackward));
      EXPECT_EQ(fwd.from, s.frames[i - 1]->stamp);
      EXPECT_EQ(bwd.from, s.frames[i]->stamp);
      for (float v : fwd.uv) EXPECT_NE(v, -12345.0f);
      for (uint8_t v : bwd.visible) EXPECT_NE(v, 77);
      EXPECT_TRUE(std::isfinite(fwd.uv[2 * 2])) << "the car's pixel has flow";
    }
  }
}

// The nodes run each step on its own (their own meshes, their own camera of the draws, objects
// passed between them): the pipeline on one decoded frame gives the same.
TEST(GroundTruthPipeline, SameAsTheStepsOneByOne) {
  Sequence s;
  GroundTruthSettings settings;
  settings.flow.wide_baseline = 2;
  GroundTruthPipeline pipeline(s.labels, s.classes, settings);
  pipeline.addMeshes({s.car_mesh});
  InstancesStep instances(s.labels, s.classes, settings.instances);
  instances.addMeshes({s.car_mesh});
  BoxesStep boxes(s.classes);
  OdometryStep odometry;
  FlowStep flow(settings.flow);
  MeshRegistry meshes;
  meshes.add(s.car_mesh);
  GroundTruthResult out;
  InstanceFrame one_by_one;
  for (const GroundTruthInputPtr& frame : s.frames) {
    VectorSink a, b;
    StepProblems pa, pb;
    ASSERT_TRUE(pipeline.process(frame, InstanceImagesInto(), a, out, pa));
    EgoFrame ego;
    ASSERT_TRUE(odometry.process(chooseFrameCamera(frame->frame), frame->stamp, frame->frame.number, ego, pb));
    ASSERT_TRUE(instances.process(frame->frame, frame->stamp, frame->draw_ids, InstanceImagesInto(), one_by_one, pb));
    FrameBoxes fb;
    boxes.process(frame->frame, frame->stamp, chooseFrameCamera(frame->frame), one_by_one.objects, meshes, fb, pb);
    FlowStep::Output fo;
    ASSERT_TRUE(flow.process(frame, chooseFrameCamera(frame->frame), one_by_one.objects, meshes, FlowStep::Want(), b,
                             fo, pb));
    EXPECT_EQ(pa.size(), pb.size());
    EXPECT_EQ(out.ego->pose.map_from_body.matrix(), ego.pose.map_from_body.matrix());
    EXPECT_EQ(out.instances.semantic, one_by_one.semantic);
    EXPECT_EQ(out.instances.instance_ids, one_by_one.instance_ids);
    ASSERT_EQ(out.boxes.boxes.size(), fb.boxes.size());
    for (size_t i = 0; i < fb.boxes.size(); ++i) {
      EXPECT_EQ(out.boxes.boxes[i].in_map.center, fb.boxes[i].in_map.center);
      EXPECT_EQ(out.boxes.boxes[i].velocity_optical, fb.boxes[i].velocity_optical);
    }
    EXPECT_EQ(out.flow.forward, fo.forward);
    EXPECT_EQ(out.flow.wide, fo.wide);
    ASSERT_EQ(a.flows.size(), b.flows.size());
    for (const auto& [kind, f] : b.flows) {
      EXPECT_EQ(a.flows.at(kind).from, f.from);
      EXPECT_EQ(0, std::memcmp(a.flows.at(kind).uv.data(), f.uv.data(), f.uv.size() * sizeof(float)));
      EXPECT_EQ(a.flows.at(kind).visible, f.visible);
    }
  }
  EXPECT_TRUE(out.flow.wide) << "frame 3: the flow from frame 1";
}

TEST(GroundTruthPipeline, FramesOutOfOrderOrWithoutIdsAreDroppedAndNamed) {
  Sequence s;
  GroundTruthPipeline pipeline(s.labels, s.classes, GroundTruthSettings());
  pipeline.addMeshes({s.car_mesh});
  GroundTruthResult out;
  VectorSink sink;
  StepProblems problems;
  ASSERT_TRUE(pipeline.process(s.frames[1], InstanceImagesInto(), sink, out, problems));
  // A frame from the past: every step names it, none takes it.
  problems.clear();
  EXPECT_FALSE(pipeline.process(s.frames[0], InstanceImagesInto(), sink, out, problems));
  EXPECT_FALSE(out.ego);
  EXPECT_EQ(count(problems, "stamp_order"), 2u) << "odometry and instances";
  // A frame without draw ids: its pose, but no instances, boxes or flow.
  problems.clear();
  EXPECT_FALSE(pipeline.process(s.frame(2, 2, false), InstanceImagesInto(), sink, out, problems));
  EXPECT_TRUE(out.ego);
  EXPECT_TRUE(out.boxes.boxes.empty());
  EXPECT_FALSE(out.flow.forward);
  // The next frame goes on; the flow step never saw the frame without ids: a gap (as when the
  // nodes' synchroniser never brought a frame), no flow spans it.
  problems.clear();
  ASSERT_TRUE(pipeline.process(s.frames[3], InstanceImagesInto(), sink, out, problems));
  EXPECT_EQ(count(problems, "gap"), 1u) << "frame 3 follows frame 1";
  EXPECT_FALSE(out.flow.forward);
}

TEST(GroundTruthPipeline, NoFlowWhenItIsOff) {
  Sequence s;
  GroundTruthSettings settings;
  settings.flow_enabled = false;
  GroundTruthPipeline pipeline(s.labels, s.classes, settings);
  GroundTruthResult out;
  VectorSink sink;
  StepProblems problems;
  for (const GroundTruthInputPtr& f : s.frames) ASSERT_TRUE(pipeline.process(f, InstanceImagesInto(), sink, out, problems));
  EXPECT_TRUE(sink.flows.empty());
  EXPECT_FALSE(out.flow.forward);
}

// The flow step's scene flow: taken from the sink only when asked for; then beside the forward flow
// (computed for it although not asked for), NaN exactly where that flow is, and the motion the
// sequence has: the road does not move (the camera does), the car drives 0.5 m along x a frame,
// both stay 10 m away (depth change 0).
class SceneFlowSink : public VectorSink {
 public:
  float* takeSceneFlow(const GroundTruthInput& from) override {
    scene.assign(kSceneFlowChannels * from.frame.pixelCount(), -12345.0f);
    ++taken;
    return scene.data();
  }
  std::vector<float> scene;
  int taken = 0;
};

TEST(GroundTruthPipeline, FlowStepGivesTheSceneFlowOnlyWhenAsked) {
  Sequence s;
  FlowStep step{FlowSettings()};
  MeshRegistry meshes;
  meshes.add({s.car_mesh});
  std::vector<TrackedObject> objects(2);
  objects[0].object.draws = {0};  // the road: stuff
  objects[1].track_id = 1, objects[1].object.draws = {1};
  FlowStep::Want plain, scene_only;
  scene_only.forward = scene_only.backward = scene_only.wide = false;
  scene_only.scene_flow = true;
  for (size_t i = 0; i < s.frames.size(); ++i) {
    const FrameCamera camera{s.frames[i]->frame.draws[0].view, s.frames[i]->frame.draws[0].projection, 0};
    SceneFlowSink sink;
    FlowStep::Output out;
    StepProblems problems;
    ASSERT_TRUE(step.process(s.frames[i], camera, objects, meshes, i % 2 ? plain : scene_only, sink, out, problems));
    EXPECT_TRUE(problems.empty());
    if (i == 0 || i % 2) {
      EXPECT_EQ(sink.taken, 0) << "frame " << i;
      EXPECT_FALSE(out.scene_flow);
      continue;
    }
    ASSERT_EQ(sink.taken, 1);
    ASSERT_TRUE(out.scene_flow && out.forward);
    EXPECT_FALSE(out.backward);
    const std::vector<float>& uv = sink.flows[static_cast<int>(FlowKind::kForward)].uv;
    const std::vector<uint32_t>& ids = *s.ids[i - 1];
    size_t road = 0, car = 0;
    for (size_t p = 0; p < kW * kH; ++p) {
      const float* v = &sink.scene[kSceneFlowChannels * p];
      ASSERT_EQ(std::isnan(v[0]), std::isnan(uv[2 * p])) << "pixel " << p;
      if (std::isnan(v[0])) continue;
      const float dx = ids[p] == 2 ? 0.5f : 0.0f;
      EXPECT_NEAR(v[0], dx, 1e-5) << "pixel " << p;
      EXPECT_NEAR(v[1], 0.0f, 1e-5) << "pixel " << p;
      EXPECT_NEAR(v[2], 0.0f, 1e-5) << "pixel " << p;
      EXPECT_NEAR(v[3], 0.0f, 1e-5) << "pixel " << p;
      ++(ids[p] == 2 ? car : road);
    }
    EXPECT_EQ(road, 12u);
    EXPECT_EQ(car, 4u);
  }
}

// Normals and clouds into vectors, counting what was taken.
class ModalityVectors : public ModalitySink {
 public:
  float* takeNormals(const GroundTruthInput& frame) override {
    normals.assign(3 * frame.frame.pixelCount(), -12345.0f);
    ++normals_taken;
    return normals.data();
  }
  CloudPoint* takeCloud(const GroundTruthInput&, const CloudSize& size) override {
    cloud.assign(size.points(), CloudPoint{-1, -1, -1, -1, 7, 7});
    ++clouds_taken;
    return cloud.data();
  }
  std::vector<float> normals;
  std::vector<CloudPoint> cloud;
  int normals_taken = 0, clouds_taken = 0;
};

bool sameFloats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(GroundTruthPipeline, ModalitiesAreTheirStepsOwn) {
  Sequence s;
  // Colours for the cloud.
  std::vector<std::vector<uint8_t>> colors;
  for (GroundTruthInputPtr& f : s.frames) {
    colors.emplace_back(3 * kW * kH);
    for (size_t i = 0; i < colors.back().size(); ++i) colors.back()[i] = static_cast<uint8_t>(i * 7 + colors.size());
    auto in = std::make_shared<GroundTruthInput>(*f);
    in->color_rgb = colors.back().data();
    f = in;
  }
  GroundTruthSettings settings;
  settings.normals = true;
  settings.cloud_decimation = 3;
  settings.amodal = true;
  settings.scene_flow = true;
  GroundTruthPipeline pipeline(s.labels, s.classes, settings);
  pipeline.addMeshes({s.car_mesh});
  InstancesStep instances(s.labels, s.classes, settings.instances);
  instances.addMeshes({s.car_mesh});
  FlowStep flow(settings.flow);
  AmodalStep amodal(settings.amodal_options);
  MeshRegistry meshes;
  meshes.add(s.car_mesh);
  GroundTruthResult out;
  InstanceFrame one_by_one;
  size_t amodal_objects = 0;
  for (size_t i = 0; i < s.frames.size(); ++i) {
    const GroundTruthInputPtr& frame = s.frames[i];
    SceneFlowSink a, b;
    ModalityVectors m;
    StepProblems pa, pb;
    ASSERT_TRUE(pipeline.process(frame, InstanceImagesInto(), a, out, pa, nullptr, &m));
    ASSERT_TRUE(instances.process(frame->frame, frame->stamp, frame->draw_ids, InstanceImagesInto(), one_by_one, pb));
    const std::optional<FrameCamera> camera = chooseFrameCamera(frame->frame);

    std::vector<float> normals(3 * kW * kH);
    EXPECT_EQ(out.normals, NormalsStep().process(*frame, camera, meshes, normals.data(), pb));
    EXPECT_TRUE(out.normals);
    EXPECT_EQ(m.normals_taken, 1);
    EXPECT_TRUE(sameFloats(m.normals, normals));

    const CloudSize size = cloudSize(kW, kH, 3);
    std::vector<CloudPoint> cloud(size.points());
    CloudImages images{kW, kH, frame->depth_m, colors[i].data(), one_by_one.semantic.data(),
                       one_by_one.instance_ids.data()};
    labelledCloud(images, intrinsicsFromGlProjection(camera->projection, kW, kH), 3, cloud.data());
    ASSERT_TRUE(out.cloud);
    ASSERT_EQ(m.cloud.size(), cloud.size());
    EXPECT_EQ(0, std::memcmp(m.cloud.data(), cloud.data(), cloud.size() * sizeof(CloudPoint)));

    FrameAmodal fa;
    amodal.process(frame->frame, one_by_one.objects, one_by_one.instance_ids.data(), meshes, fa, pb);
    ASSERT_EQ(out.amodal.objects.size(), fa.objects.size());
    for (size_t o = 0; o < fa.objects.size(); ++o) {
      EXPECT_EQ(out.amodal.objects[o].track_id, fa.objects[o].track_id);
      EXPECT_EQ(out.amodal.objects[o].mask, fa.objects[o].mask);
      EXPECT_EQ(out.amodal.objects[o].visible_pixels, fa.objects[o].visible_pixels);
    }
    amodal_objects += fa.objects.size();

    FlowStep::Want want;
    want.scene_flow = true;
    FlowStep::Output fo;
    ASSERT_TRUE(flow.process(frame, camera, one_by_one.objects, meshes, want, b, fo, pb));
    EXPECT_EQ(out.flow.scene_flow, fo.scene_flow);
    EXPECT_EQ(out.flow.scene_flow, i > 0);
    EXPECT_TRUE(sameFloats(a.scene, b.scene));
    EXPECT_EQ(pa.size(), pb.size());
  }
  EXPECT_EQ(amodal_objects, s.frames.size()) << "the car, every frame";
}

TEST(GroundTruthPipeline, ModalitiesNotAskedForAreNotComputed) {
  Sequence s;
  GroundTruthPipeline pipeline(s.labels, s.classes, GroundTruthSettings());
  pipeline.addMeshes({s.car_mesh});
  GroundTruthResult out;
  for (const GroundTruthInputPtr& f : s.frames) {
    SceneFlowSink sink;
    ModalityVectors m;
    StepProblems problems;
    ASSERT_TRUE(pipeline.process(f, InstanceImagesInto(), sink, out, problems, nullptr, &m));
    EXPECT_EQ(m.normals_taken + m.clouds_taken + sink.taken, 0);
    EXPECT_FALSE(out.normals || out.cloud || out.flow.scene_flow);
    EXPECT_TRUE(out.amodal.objects.empty());
  }
}

}  // namespace
}  // namespace viper
