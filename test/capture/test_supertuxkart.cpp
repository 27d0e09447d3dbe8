// SuperTuxKart (Debian's supertuxkart 1.4: a program whose source and assets are not ours) under
// the capture layer, checked without an oracle. A short AI race is recorded once with apitrace,
// then replayed (glretrace: the same frames every time) plainly and under capture, so that the
// game's own image can be compared frame by frame, and the capture checked against itself:
// reprojection of every id pixel, flow forward-backward and photometric consistency, instances.
// Both of the game's pipelines: forward (config/profiles/supertuxkart.yaml) and deferred.
#include "capture_checks.h"
#include "../common/process_util.h"
#include "viper/capture/content_key.h"
#include "viper/ground_truth/instance_pipeline.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using viper::CaptureFrame;

namespace {

constexpr int kWidth = 480, kHeight = 270;
const char* kGame = "/usr/games/supertuxkart";

using viper::test::run;
std::string tempDir() { return viper::test::tempDir("viper_stk_"); }

// Each command in its own X server, the screen larger than the window (the game shrinks a window
// that does not fit).
std::string xvfb() {
  return "xvfb-run -a -s '-screen 0 " + std::to_string(kWidth + 64) + "x" + std::to_string(kHeight + 64) + "x24' ";
}

struct PipelineRun {
  bool ok = false;
  std::string problem;
  std::vector<std::string> plain, captured;  // glretrace's snapshots (PNG), frame by frame
  std::vector<std::string> plain_again;       // a second plain replay: what the game leaves undefined differs
  std::vector<CaptureFrame> frames;
  viper::MeshRegistry meshes;
};

// Traces a 2 s race (after loading) with `pipeline` (--disable-dynamic-lights or
// --enable-dynamic-lights), replays it plainly and under capture with snapshots of every frame.
const PipelineRun& runPipeline(const std::string& pipeline) {
  static std::map<std::string, PipelineRun> runs;
  auto it = runs.find(pipeline);
  if (it != runs.end()) return it->second;
  PipelineRun& r = runs[pipeline];
  const std::string d = tempDir() + "/" + pipeline.substr(2, 7);
  fs::create_directories(d + "/home");
  fs::create_directories(d + "/plain");
  fs::create_directories(d + "/plain_again");
  fs::create_directories(d + "/captured");
  // A fresh configuration (HOME) so that nothing a user set changes what is drawn.
  const std::string trace = "HOME=" + d + "/home " + xvfb() + "apitrace trace -o " + d + "/race.trace " + kGame +
                            " --track=candela_city --numkarts=4 --seed=1 --profile-time=2 --anisotropic=0 " +
                            pipeline + " --windowed --screensize=" + std::to_string(kWidth) + "x" +
                            std::to_string(kHeight) + " > " + d + "/trace.log 2>&1";
  if (run(trace) != 0) {
    r.problem = "apitrace of the game failed: " + d + "/trace.log";
    return r;
  }
  // In a sanitized build the plain replays run with the runtime `capture` preloads for the layer:
  // Mesa or glretrace reads heap memory it never wrote in the deferred pipeline's first frame, and
  // ASan's malloc fill changes 1270 of its pixels (up to 190 levels) with the runtime alone.
  const std::string runtime = viper::test::sanitizerPreload();
  if (run(xvfb() + runtime + "glretrace -b -s " + d + "/plain/ " + d + "/race.trace > " + d + "/plain.log 2>&1") != 0) {
    r.problem = "plain replay failed: " + d + "/plain.log";
    return r;
  }
  if (run(xvfb() + runtime + "glretrace -b -s " + d + "/plain_again/ " + d + "/race.trace > " + d + "/plain_again.log 2>&1") !=
      0) {
    r.problem = "second plain replay failed: " + d + "/plain_again.log";
    return r;
  }
  const std::string capture = std::string(VIPER_CAPTURE_EXE) + " --output " + d + "/race.vcap --profile " +
                              VIPER_PROFILE_DIR "/supertuxkart.yaml --start-on-scene -- ";
  if (run(xvfb() + capture + "glretrace -b -s " + d + "/captured/ " + d + "/race.trace > " + d + "/captured.log 2>&1") != 0) {
    r.problem = "replay under capture failed: " + d + "/captured.log";
    return r;
  }
  for (const auto& [dir, list] : {std::make_pair(d + "/plain", &r.plain), std::make_pair(d + "/plain_again", &r.plain_again),
                                  std::make_pair(d + "/captured", &r.captured)}) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().string());
    list->assign(names.begin(), names.end());
  }
  viper::test::readCapture(d + "/race.vcap", r.frames, r.meshes);
  r.ok = true;
  return r;
}

struct ImageComparison {
  size_t pixels = 0, identical = 0, within_one = 0;
  int max_difference = 0;
  size_t frames = 0, undefined_frames = 0;  // frames compared; frames the game itself leaves undefined
};

// The game's image without and with capture, frame by frame. A frame whose two plain replays differ
// is one the game draws from memory it never wrote (the first loading frame shows such garbage on
// llvmpipe): it says nothing about the capture layer and is left out, and counted.
ImageComparison compareSnapshots(const PipelineRun& r) {
  ImageComparison c;
  for (size_t i = 0; i < r.plain.size() && i < r.captured.size(); ++i) {
    const cv::Mat a = cv::imread(r.plain[i]), b = cv::imread(r.captured[i]);
    if (a.empty() || a.size() != b.size()) continue;
    if (i < r.plain_again.size()) {
      const cv::Mat again = cv::imread(r.plain_again[i]);
      if (again.size() != a.size() || cv::norm(a, again, cv::NORM_INF) != 0) {
        ++c.undefined_frames;
        continue;
      }
    }
    ++c.frames;
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    for (int y = 0; y < diff.rows; ++y)
      for (int x = 0; x < diff.cols; ++x) {
        const cv::Vec3b v = diff.at<cv::Vec3b>(y, x);
        const int m = std::max({v[0], v[1], v[2]});
        ++c.pixels;
        c.identical += m == 0;
        c.within_one += m <= 1;
        c.max_difference = std::max(c.max_difference, m);
      }
  }
  return c;
}

// The traces (about 100 MB each) and snapshots go when every test passed; kept for a look otherwise.
class CleanUp : public testing::Environment {
 public:
  void TearDown() override {
    if (testing::UnitTest::GetInstance()->Passed()) fs::remove_all(tempDir());
  }
};
const testing::Environment* const kCleanUp = testing::AddGlobalTestEnvironment(new CleanUp);

// The shipped label table (config/labels, made from an OpenGL capture) through the instance
// pipeline over a run's frames: id pixels with a class, car (class 24) tracks, objects in their boxes.
struct Labelled {
  uint64_t id_pixels = 0, labelled = 0;
  std::map<int32_t, size_t> car_frames;  ///< track -> frames it is seen in
  size_t longest = 0;                    ///< frames of the longest car track
  viper::BoxCheck boxes;
};
Labelled labelWithShippedTable(const PipelineRun& r) {
  Labelled l;
  viper::InstancePipeline pipeline(viper::LabelTable::load(VIPER_STK_LABELS));
  for (const CaptureFrame& f : r.frames) {
    const viper::InstanceFrame g = pipeline.process(f);
    std::vector<viper::FrameObject> objects;
    for (const viper::TrackedObject& o : g.objects) objects.push_back(o.object);
    l.boxes.add(viper::checkBoxes(f, objects, r.meshes));
    for (size_t i = 0; i < f.draw_ids.size(); ++i)
      if (f.draw_ids[i]) ++l.id_pixels, l.labelled += g.semantic[i] != 0;
    for (const viper::TrackedObject& o : g.objects)
      if (o.track_id > 0 && o.object.class_id == 24 && o.object.pixel_count > 0) ++l.car_frames[o.track_id];
  }
  for (const auto& [id, n] : l.car_frames) l.longest = std::max(l.longest, n);
  return l;
}

void requireTools() {
  for (const char* tool : {kGame, "/usr/bin/apitrace", "/usr/bin/glretrace", "/usr/bin/xvfb-run"})
    ASSERT_TRUE(fs::exists(tool)) << tool << " is missing: run 'bash scripts/setup.sh --test-programs'";
}

// Flow of consecutive frames, both ways: back where it came from, and b's colors where it lands.
// Static surfaces (the same mesh at the same place in both frames) move as the camera does. The
// OpenGL capture's (`opengl`) also has flow on 85 % of its id pixels and its static surfaces' median
// error within 1e-3 px.
void expectFlowHolds(const PipelineRun& r, bool opengl) {
  const viper::test::FlowSequenceCheck flow_check = viper::test::checkFlowSequence(r.frames, r.meshes);
  ASSERT_EQ(flow_check.problem, "");
  flow_check.print();
  const viper::FlowConsistencyCheck& flow = flow_check.flow;
  if (opengl) {
    EXPECT_GE(flow.flow_pixels, 0.85 * flow.id_pixels);
  }
  EXPECT_GE(flow.forward_backward_px.size(), 100000u);
  EXPECT_LE(viper::quantile(flow.forward_backward_px, 0.5), 0.01f);
  EXPECT_GE(flow_check.withinHalfPixel(), 0.99);
  EXPECT_LT(flow.photometricFlow(), 0.5 * flow.photometricZero());
  EXPECT_GE(flow_check.statics.static_pixels, flow.id_pixels / 2);
  if (opengl) {
    EXPECT_LE(viper::quantile(flow_check.statics.error_px, 0.5), 1e-3f);
  }
  EXPECT_LE(viper::quantile(flow_check.statics.error_px, 0.99), 1e-2f);
  // Scene flow against the flow and the depths (measured: reprojection p99 2.2e-5 px, depth p99
  // 8.1e-6 relative, static surfaces 3.2e-13 of their depth at most).
  viper::test::expectSceneFlowHolds(flow_check);
}

void checkCapture(const PipelineRun& r) {
  ASSERT_TRUE(r.ok) << r.problem;
  ASSERT_GE(r.frames.size(), 10u) << "the race's frames (from the first with the camera's matrices)";
  viper::ReprojectionCheck all;
  for (const CaptureFrame& f : r.frames) {
    EXPECT_EQ(viper::validateFrame(f), "") << "frame " << f.number;
    all.add(viper::checkReprojection(f, r.meshes));
  }
  std::printf("reprojection: scene %.1f%% of pixels, id %.2f%%, placed %.2f%%, checked %llu, distance <= 0.5 px "
              "%.4f%%, depth rel. median %.2e p99 %.2e\n",
              100.0 * all.scene_pixels / all.pixels, 100.0 * all.id_pixels / all.scene_pixels,
              100.0 * all.placed_pixels / all.scene_pixels, static_cast<unsigned long long>(all.checked_pixels),
              100.0 * std::count_if(all.distance_px.begin(), all.distance_px.end(), [](float d) { return d <= 0.5f; }) /
                  all.distance_px.size(),
              viper::quantile(all.depth_relative, 0.5), viper::quantile(all.depth_relative, 0.99));
  EXPECT_GE(all.id_pixels, 0.95 * all.scene_pixels) << "scene pixels with a draw id";
  EXPECT_GE(all.placed_pixels, 0.85 * all.scene_pixels) << "scene pixels whose draw has a mesh and its matrices";
  EXPECT_LE(viper::quantile(all.distance_px, 0.999), 0.5f) << "id pixels off their projected triangle";
  EXPECT_LE(viper::quantile(all.depth_relative, 0.99), 1e-4f) << "depth of the projected triangle vs the depth image";

  // Every instance of an instanced draw is its own draw, placed where its own attributes say.
  size_t instanced_frames = 0;
  for (const CaptureFrame& f : r.frames) {
    std::map<uint64_t, std::set<std::vector<float>>> placements;  // mesh -> distinct world matrices
    for (const viper::DrawRecord& d : f.draws)
      if (d.mesh_key && d.visible_pixels > 0 && (d.matrix_flags & viper::kHasWorld))
        placements[d.mesh_key].insert(std::vector<float>(d.world.data(), d.world.data() + 16));
    for (const auto& [mesh, worlds] : placements)
      if (worlds.size() >= 2) {
        ++instanced_frames;
        break;
      }
  }
  EXPECT_GE(instanced_frames, r.frames.size() / 2) << "frames with a mesh visible at two places";
}

}  // namespace

TEST(SuperTuxKart, ForwardPipelineGroundTruthHoldsAgainstItself) {
  requireTools();
  const PipelineRun& r = runPipeline("--disable-dynamic-lights");
  checkCapture(r);
  if (HasFatalFailure()) return;
  expectFlowHolds(r, /*opengl=*/true);
  if (HasFatalFailure()) return;

  // The shipped label table (made from another, longer capture at another size) labels this one:
  // resource keys are the game's content, whatever the run. The followed kart keeps one track.
  const Labelled l = labelWithShippedTable(r);
  const uint64_t id_pixels = l.id_pixels, labelled = l.labelled;
  const size_t longest = l.longest;
  const std::map<int32_t, size_t>& car_frames = l.car_frames;
  const viper::BoxCheck& boxes = l.boxes;
  std::printf("labels: %.2f%% of id pixels have a class; %zu car tracks, the longest in %zu of %zu frames\n",
              100.0 * labelled / id_pixels, car_frames.size(), longest, r.frames.size());
  EXPECT_GE(labelled, 0.99 * id_pixels);
  EXPECT_EQ(longest, r.frames.size()) << "the kart the camera follows keeps its id in every frame";
  // Every object's pixels (their depth) lie in its box (from its meshes, parts attached).
  std::printf("boxes: %llu objects, %llu pixels, outside their box by (relative to distance) median %.2e p99 %.2e "
              "p99.9 %.2e max %.2e\n",
              static_cast<unsigned long long>(boxes.objects), static_cast<unsigned long long>(boxes.pixels),
              viper::quantile(boxes.outside_relative, 0.5), viper::quantile(boxes.outside_relative, 0.99),
              viper::quantile(boxes.outside_relative, 0.999), viper::quantile(boxes.outside_relative, 1.0));
  EXPECT_GE(boxes.pixels, id_pixels / 2);
  EXPECT_LE(viper::quantile(boxes.outside_relative, 0.999), 1e-4f);

  // The capture's color is the scene without the HUD: mostly the game's image, but not all of it.
  const cv::Mat last = cv::imread(r.captured.back());
  const CaptureFrame& f = r.frames.back();
  ASSERT_EQ(last.cols, static_cast<int>(f.width));
  size_t same = 0;
  for (int y = 0; y < last.rows; ++y)
    for (int x = 0; x < last.cols; ++x) {
      const cv::Vec3b bgr = last.at<cv::Vec3b>(y, x);
      const uint8_t* rgb = &f.color_rgb[(static_cast<size_t>(y) * f.width + x) * 3];
      same += std::abs(bgr[2] - rgb[0]) <= 1 && std::abs(bgr[1] - rgb[1]) <= 1 && std::abs(bgr[0] - rgb[2]) <= 1;
    }
  const double same_fraction = static_cast<double>(same) / (f.width * f.height);
  std::printf("last frame: %.2f%% of the capture's color equals the game's image (the rest: its HUD)\n",
              100.0 * same_fraction);
  EXPECT_GT(same_fraction, 0.85);
  EXPECT_LT(same_fraction, 0.999) << "the HUD (timer, minimap, icons) is not in the capture's color";

  // The game's own image under capture. Forward rendering draws the scene into the window, which
  // the layer replaces by a framebuffer object; on llvmpipe that changes blended and interpolated
  // colors by one level on about 1 % of pixels (docs/capture_layer.md, "The program's image").
  const ImageComparison c = compareSnapshots(r);
  std::printf("game image under capture: %zu frames (%zu left undefined by the game itself), %zu pixels, identical "
              "%.4f%%, within 1 level %.4f%%, max %d\n", c.frames, c.undefined_frames, c.pixels,
              100.0 * c.identical / c.pixels, 100.0 * c.within_one / c.pixels, c.max_difference);
  ASSERT_EQ(r.plain.size(), r.captured.size()) << "frames replayed";
  EXPECT_LE(c.undefined_frames, c.frames / 20) << "most frames must be defined by the game to compare them";
  EXPECT_GE(c.identical, 0.98 * c.pixels);
  EXPECT_GE(c.within_one, 0.9995 * c.pixels);
}

TEST(SuperTuxKart, DeferredPipelineIdsFromTheGBufferAndTheSameImage) {
  requireTools();
  const PipelineRun& r = runPipeline("--enable-dynamic-lights");
  checkCapture(r);
  if (HasFatalFailure()) return;
  // The scene is drawn into the game's own framebuffers (the G-buffer holds its normals at draw
  // buffer 1, ours is 7): identical; only what is drawn into the window (HUD text) may differ by one.
  const ImageComparison c = compareSnapshots(r);
  std::printf("game image under capture (deferred): %zu frames (%zu left undefined by the game itself), %zu pixels, "
              "identical %.4f%%, max difference %d\n", c.frames, c.undefined_frames, c.pixels,
              100.0 * c.identical / c.pixels, c.max_difference);
  ASSERT_EQ(r.plain.size(), r.captured.size()) << "frames replayed";
  EXPECT_LE(c.undefined_frames, c.frames / 20) << "most frames must be defined by the game to compare them";
  EXPECT_GE(c.identical, 0.999 * c.pixels);
  EXPECT_LE(c.max_difference, 1);
}

// The game's Vulkan renderer (--render-driver=vulkan, on lavapipe) under the Vulkan layer
// (config/profiles/supertuxkart_vulkan.yaml), from the first frame of the race. Captured live, not
// replayed (Debian ships no Vulkan trace replayer), so the game's own image is not compared here:
// test_capture_vulkan does that on our Vulkan program.
TEST(SuperTuxKart, VulkanRendererGroundTruthHoldsAgainstItself) {
  for (const char* tool : {kGame, "/usr/bin/xvfb-run", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json"})
    ASSERT_TRUE(fs::exists(tool)) << tool << " is missing: run 'bash scripts/setup.sh --test-programs'";
  PipelineRun r;
  const std::string d = tempDir() + "/vulkan";
  fs::create_directories(d + "/home");
  const std::string command = "HOME=" + d + "/home ALSOFT_DRIVERS=null " + xvfb() + VIPER_CAPTURE_EXE + " --output " + d +
                              "/race.vcap --profile " VIPER_PROFILE_DIR "/supertuxkart_vulkan.yaml --start-on-scene " +
                              "--frames 12 -- " + kGame +
                              " --render-driver=vulkan --track=candela_city --numkarts=4 --seed=1 --profile-time=120 "
                              "--windowed --screensize=" +
                              std::to_string(kWidth) + "x" + std::to_string(kHeight) + " > " + d + "/game.log 2>&1";
  ASSERT_EQ(run(command), 0) << "the game under capture failed: " << d << "/game.log";
  viper::test::readCapture(d + "/race.vcap", r.frames, r.meshes);
  r.ok = true;
  checkCapture(r);
  if (HasFatalFailure()) return;
  // What the layer could not record is said per draw: every recorded draw has its ids and matrices;
  // the ones without a mesh are the sky (no vertex buffer) and the deforming programs (drivers,
  // foliage: no deformed positions from the Vulkan layer yet).
  for (const CaptureFrame& f : r.frames)
    for (const viper::DrawRecord& draw : f.draws) {
      EXPECT_EQ(draw.gaps & viper::kGapNoIds, 0) << "frame " << f.number << " draw " << draw.index;
      EXPECT_EQ(draw.gaps & viper::kGapMatrixMissing, 0) << "frame " << f.number << " draw " << draw.index;
    }
  // Texture keys: the content of the images the program uploaded, the same for a mesh in every frame.
  size_t visible = 0, textured = 0, unstable = 0;
  std::map<uint64_t, std::vector<uint64_t>> textures_of_mesh;
  for (const CaptureFrame& f : r.frames)
    for (const viper::DrawRecord& draw : f.draws) {
      if (!draw.visible_pixels || !draw.mesh_key) continue;
      ++visible;
      // Images the program rendered (shadow maps, render targets) have no key: one uploaded is enough.
      textured += std::count(draw.texture_keys.begin(), draw.texture_keys.end(), 0u) <
                  static_cast<long>(draw.texture_keys.size());
      auto [it, inserted] = textures_of_mesh.emplace(viper::combineKeys(draw.mesh_key, draw.program_key), draw.texture_keys);
      unstable += !inserted && it->second != draw.texture_keys;
    }
  std::printf("texture keys: %zu of %zu visible draws with a mesh have an uploaded texture's; %zu differ from their mesh's first\n",
              textured, visible, unstable);
  EXPECT_GE(textured, 0.9 * visible);
  EXPECT_EQ(unstable, 0u) << "a mesh's texture keys changed between frames";

  // Content keys do not depend on the API: the label table made from an OpenGL capture labels the
  // Vulkan capture (all but the sky and the deforming drivers, which have no mesh from the Vulkan
  // layer yet), the followed kart keeps one track, and every object's pixels lie in its box.
  const Labelled l = labelWithShippedTable(r);
  const uint64_t id_pixels = l.id_pixels, labelled = l.labelled;
  const size_t longest = l.longest;
  const std::map<int32_t, size_t>& car_frames = l.car_frames;
  const viper::BoxCheck& boxes = l.boxes;
  std::printf("labels from the OpenGL capture's table: %.2f%% of id pixels have a class; %zu car tracks, the longest "
              "in %zu of %zu frames; boxes p99.9 %.2e\n",
              100.0 * labelled / id_pixels, car_frames.size(), longest, r.frames.size(),
              viper::quantile(boxes.outside_relative, 0.999));
  EXPECT_GE(labelled, 0.85 * id_pixels);
  EXPECT_EQ(longest, r.frames.size()) << "the kart the camera follows keeps its id in every frame";
  EXPECT_LE(viper::quantile(boxes.outside_relative, 0.999), 1e-4f);
  expectFlowHolds(r, /*opengl=*/false);
}
