// capture_check: how much of a capture's scene has ids, matrices and meshes, and how well they agree
// with its depth image (viper::checkReprojection), for captures of programs without an oracle. Each
// check is judged against its goal, or named as not run with the reason.
// Exit code 0 = every check that ran met its goal, 1 = damaged (figures up to the damage printed),
// 2 = usage/open error, 3 = a check missed its goal, 4 = no check could run.
#include "command_line.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/ground_truth/capture_verdict.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/instance_pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>

namespace {

// Share of `distances` at most 0.5 px (0 when there is none).
double withinHalfPixel(const std::vector<float>& distances) {
  size_t within = 0;
  for (float d : distances) within += d <= 0.5f;
  return distances.empty() ? 0.0 : static_cast<double>(within) / distances.size();
}

void print(const char* label, const viper::ReprojectionCheck& c) {
  const double scene = c.scene_pixels ? static_cast<double>(c.scene_pixels) : 1.0;
  std::printf("%s scene %5.1f%% of pixels | id %5.1f%% | placed %5.1f%% | checked %llu px: distance median %.3f "
              "p99 %.3f px, <= 0.5 px %.2f%% | depth rel. median %.2e p99 %.2e (%llu px at the far plane: no depth)\n",
              label, 100.0 * c.scene_pixels / (c.pixels ? c.pixels : 1), 100.0 * c.id_pixels / scene,
              100.0 * c.placed_pixels / scene, static_cast<unsigned long long>(c.checked_pixels),
              viper::quantile(c.distance_px, 0.5), viper::quantile(c.distance_px, 0.99),
              100.0 * withinHalfPixel(c.distance_px),
              viper::quantile(c.depth_relative, 0.5), viper::quantile(c.depth_relative, 0.99),
              static_cast<unsigned long long>(c.far_plane_pixels));
}

void printGaps(const viper::CaptureGaps& g) {
  std::printf("gaps the layer reported: of %llu recorded draws, %llu without ids (shader not rewritten, or no program while a query counted), %llu missing "
              "a matrix the profile names (%llu px), %llu without mesh (%llu px); %llu draws into the scene not "
              "recorded (immediate mode, display lists, no program and no depth test, or a multi-draw reading gl_DrawID)\n",
              static_cast<unsigned long long>(g.draws), static_cast<unsigned long long>(g.no_ids),
              static_cast<unsigned long long>(g.matrix_missing), static_cast<unsigned long long>(g.matrix_missing_pixels),
              static_cast<unsigned long long>(g.no_mesh), static_cast<unsigned long long>(g.no_mesh_pixels),
              static_cast<unsigned long long>(g.unrecorded_draws));
}

void printFlow(const viper::FlowConsistencyCheck& c, uint64_t pairs) {
  std::printf("flow of %llu pairs: defined on %5.1f%% of id pixels, visible in the next frame %5.1f%% | "
              "forward-backward median %.2e p99 %.2e px, <= 0.5 px %.2f%% | photometric error %.2f "
              "(no motion: %.2f) of 255\n",
              static_cast<unsigned long long>(pairs), 100.0 * c.flow_pixels / (c.id_pixels ? c.id_pixels : 1),
              100.0 * c.visible_pixels / (c.flow_pixels ? c.flow_pixels : 1), viper::quantile(c.forward_backward_px, 0.5),
              viper::quantile(c.forward_backward_px, 0.99),
              100.0 * withinHalfPixel(c.forward_backward_px), c.photometricFlow(),
              c.photometricZero());
}

// The goals of the checks (docs/capture_layer.md, "Checking a capture without an oracle"): far
// enough from what our programs, SuperTuxKart and Minetest measure that only a wrong capture misses
// them, not one program's depth precision or fast camera.
constexpr double kReprojectionWithinHalfPx = 0.99;  // share of checked pixels within 0.5 px of their triangle
constexpr float kDepthRelativeP99 = 1e-2f;
constexpr float kForwardBackwardMedianPx = 0.01f;
constexpr double kForwardBackwardWithinHalfPx = 0.95;
constexpr double kPhotometricAlwaysMet = 1.0;  // of 255: a warp this close is right whatever no motion gives
constexpr float kStaticFlowP99Px = 0.1f;
constexpr float kBoxesOutsideP999 = 1e-3f;

// Each check's outcome, a line each, and the exit status they make.
class Verdicts {
 public:
  void judge(const char* check, bool met, const std::string& measured, const char* goal) {
    std::printf("%s: %s: %s%s%s%s\n", check, met ? "met" : "FAILED", measured.c_str(), met ? "" : " (goal: ",
                met ? "" : goal, met ? "" : ")");
    ++(met ? met_ : failed_);
  }
  void notRun(const char* check, const std::string& why) {
    std::printf("%s: not run: %s\n", check, why.c_str());
    ++not_run_;
  }
  void notAsked(const char* checks, const char* option) { std::printf("%s: not asked (%s)\n", checks, option); }
  // 3 a check failed, 4 none ran, else 0; printed with the counts.
  int finish() const {
    const int status = failed_ ? 3 : met_ ? 0 : 4;
    std::printf("checks: %d met their goal, %d failed, %d not run\n", met_, failed_, not_run_);
    return status;
  }

 private:
  int met_ = 0, failed_ = 0, not_run_ = 0;
};

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b, c);
  return buffer;
}

void judgeReprojection(Verdicts& v, const viper::ReprojectionCheck& c, const viper::CaptureCoverage& coverage) {
  if (c.checked_pixels == 0) {
    std::string why = "no triangle of a placed draw is in front of the camera";
    if (coverage.frames == 0) why = "no frame";
    else if (c.id_pixels == 0) why = "no scene pixel has a draw id (" + viper::mainGap(coverage) + ")";
    else if (c.placed_pixels == 0) why = "no draw is placed: " + viper::unplacedReason(coverage);
    v.notRun("reprojection", why);
    v.notRun("reprojection depth", why);
    return;
  }
  const double within = withinHalfPixel(c.distance_px);
  v.judge("reprojection", within >= kReprojectionWithinHalfPx,
          format("%.2f%% of %.0f checked px within 0.5 px of their triangle", 100.0 * within,
                 static_cast<double>(c.checked_pixels)),
          ">= 99% within 0.5 px");
  const float depth = viper::quantile(c.depth_relative, 0.99);
  // Pixels at the far plane (a sky drawn there) have no depth: said, not compared.
  const std::string far = c.far_plane_pixels == 0 ? std::string() :
      format(" (%.0f px at the far plane left out: no depth there, NaN as published)", static_cast<double>(c.far_plane_pixels));
  if (std::isnan(depth)) v.notRun("reprojection depth", "no checked pixel has a depth in front of the camera" + far);
  else v.judge("reprojection depth", depth <= kDepthRelativeP99, format("p99 %.2e relative", depth) + far, "p99 <= 1e-2");
}

void judgeFlow(Verdicts& v, const viper::FlowConsistencyCheck& f, const viper::StaticFlowCheck& statics, uint64_t pairs) {
  std::string why;
  if (pairs == 0) why = "no two consecutive frames";
  else if (f.flow_pixels == 0)
    why = "no pixel has a flow into the next frame (flow needs placed draws with a perspective projection, drawn "
          "again there)";
  else if (f.forward_backward_px.empty()) why = "no pixel's flow lands visible in the next frame";
  if (!why.empty()) {
    v.notRun("flow forward-backward", why);
    v.notRun("flow photometric", why);
  } else {
    const float median = viper::quantile(f.forward_backward_px, 0.5);
    const double within = withinHalfPixel(f.forward_backward_px);
    v.judge("flow forward-backward", median <= kForwardBackwardMedianPx && within >= kForwardBackwardWithinHalfPx,
            format("median %.2e px, p99 %.2e px, %.2f%% within 0.5 px", median,
                   viper::quantile(f.forward_backward_px, 0.99), 100.0 * within),
            "median <= 0.01 px and >= 95% within 0.5 px");
    v.judge("flow photometric",
            f.photometricFlow() < f.photometricZero() || f.photometricFlow() <= kPhotometricAlwaysMet,
            format("%.2f of 255 with the flow, %.2f without motion", f.photometricFlow(), f.photometricZero()),
            "below no motion's, or <= 1 of 255");
  }
  if (pairs == 0) v.notRun("flow static surfaces", why);
  else if (statics.error_px.empty())
    v.notRun("flow static surfaces", statics.static_pixels
                                         ? "no pixel of a static surface has a flow"
                                         : "no static surface (a rigid draw with the same mesh and world in both "
                                           "frames, and view and projection)");
  else {
    const float p99 = viper::quantile(statics.error_px, 0.99);
    v.judge("flow static surfaces", p99 <= kStaticFlowP99Px,
            format("p99 %.2e px from the camera's own motion", p99), "p99 <= 0.1 px");
  }
}

// Tracks of the instance pipeline: per track id its class and the frames it was seen in.
struct TrackStats {
  uint64_t labelled_pixels = 0, id_pixels = 0;
  std::map<int32_t, std::pair<uint8_t, uint64_t>> tracks;  // id -> (class, frames seen)

  void add(const viper::CaptureFrame& f, const viper::InstanceFrame& g) {
    for (size_t i = 0; i < f.draw_ids.size(); ++i)
      if (f.draw_ids[i]) ++id_pixels, labelled_pixels += g.semantic[i] != 0;
    for (const viper::TrackedObject& o : g.objects)
      if (o.track_id > 0 && o.object.pixel_count > 0) {
        auto& t = tracks[o.track_id];
        t.first = o.object.class_id;
        ++t.second;
      }
  }

  void print(uint64_t frames) const {
    std::printf("labels: %.2f%% of id pixels have a class\n", 100.0 * labelled_pixels / (id_pixels ? id_pixels : 1));
    std::map<uint8_t, std::vector<uint64_t>> by_class;
    for (const auto& [id, t] : tracks) by_class[t.first].push_back(t.second);
    for (auto& [c, lengths] : by_class) {
      std::sort(lengths.rbegin(), lengths.rend());
      std::printf("  class %3d: %zu tracks; frames seen, longest first:", int(c), lengths.size());
      for (size_t i = 0; i < lengths.size() && i < 12; ++i) std::printf(" %llu", static_cast<unsigned long long>(lengths[i]));
      std::printf(" (of %llu frames)\n", static_cast<unsigned long long>(frames));
    }
  }
};

// A frame with what the flow needs of it.
struct FlowInput {
  viper::CaptureFrame frame;
  std::vector<float> depth_m;
  std::vector<int32_t> object_ids;  // none: draws associate by mesh and placement
};

FlowInput flowInput(const viper::CaptureFrame& f) {
  FlowInput in{f, {}, std::vector<int32_t>(f.draws.size(), 0)};
  const auto camera = viper::chooseFrameCamera(f);
  in.depth_m = viper::depthMetres(f, camera ? &*camera : nullptr);
  return in;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "For every pixel with a draw id: projects the triangle its draw and primitive id name with the recorded\n"
      "matrices (or post-vertex-shader positions) and prints how far the pixel lies from it (px) and how far\n"
      "its depth is from the triangle's (relative), with the fractions of scene pixels that have an id and a\n"
      "placed mesh, and what the layer reported it could not record (draws without ids, matrices or mesh;\n"
      "draws not recorded).",
      "capture_check");
  std::string path;
  uint64_t from = 0, max_frames = 0;
  bool per_frame = false, flow = false, resume = false;
  std::string labels;
  app.add_option("FILE.vcap", path, "the capture to check")->required()->type_name("");
  app.add_option("--from", from, "skip frames numbered below N");
  app.add_option("--frames", max_frames, "check at most N frames (0: all)");
  app.add_flag("--per-frame", per_frame, "also the figures of every frame (and every pair, with --flow)");
  app.add_flag("--flow", flow,
               "also the flow of each pair of consecutive frames both ways (viper::computeFlow, draws associated "
               "by mesh and placement): forward-backward endpoint error and the photometric error of warping "
               "the next frame by the flow, against no motion; and static surfaces (same mesh, same world) "
               "against the flow the camera's own motion gives from depth (viper::checkStaticFlow)");
  app.add_option("--labels", labels,
                 "also the instances pipeline with that label table: share of id pixels with a class, per thing "
                 "class its tracks (how many, frames each: ids stable over time), and every object's pixels "
                 "(their depth) against its 3D box (viper::checkBoxes)")
      ->type_name("L.yaml");
  app.add_flag("--resume-tracks", resume,
               "with --labels, the tracker's resume_by_resources (an object back after a long gap takes up its "
               "own id)");
  app.footer(
      "Then one line per check: 'NAME: met: ...', 'NAME: FAILED: ... (goal: ...)' or 'NAME: not run: WHY'.\n"
      "Goals: reprojection >= 99% of checked pixels within 0.5 px; reprojection depth p99 <= 1e-2 (relative);\n"
      "flow forward-backward median <= 0.01 px and >= 95% within 0.5 px; flow photometric below no motion's\n"
      "(or <= 1 of 255); flow of static surfaces p99 <= 0.1 px; boxes p99.9 <= 1e-3 of the distance outside.\n"
      "Exit status: 0 every check that ran met its goal; 1 the capture is damaged (figures up to the damage);\n"
      "2 usage or open error; 3 a check missed its goal; 4 no check could run.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  const auto reader = viper_tools::openOrReport<viper::CaptureReader>(app, path);
  if (!reader) return 2;
  viper::MeshRegistry meshes;
  viper::ReprojectionCheck all;
  viper::CaptureCoverage coverage;
  coverage.profile_given = !reader->header().profile.empty() && reader->header().profile != "<default>";
  viper::BoxCheck boxes;
  viper::FlowConsistencyCheck flow_all;
  viper::StaticFlowCheck static_all;
  uint64_t pairs = 0;
  std::unique_ptr<FlowInput> previous;
  std::unique_ptr<viper::InstancePipeline> pipeline;
  TrackStats tracks;
  viper::InstanceFrame truth;
  if (!labels.empty()) {
    try {
      viper::InstancePipelineOptions options;
      options.tracker.resume_by_resources = resume;
      pipeline = std::make_unique<viper::InstancePipeline>(viper::LabelTable::load(labels), options);
    } catch (const std::exception& e) {
      std::cerr << "capture_check: " << e.what() << "\n";
      return 2;
    }
  }
  viper::CaptureFrame frame;
  uint64_t checked_frames = 0;
  int status = 0;
  uint64_t resized_pairs = 0;
  try {
    while (reader->next(frame) == viper::CaptureReader::Status::kFrame) {
      meshes.add(frame.new_meshes);
      if (frame.number < from) continue;
      if (pipeline) {
        pipeline->process(frame, truth);
        tracks.add(frame, truth);
        std::vector<viper::FrameObject> objects;
        for (const viper::TrackedObject& o : truth.objects) objects.push_back(o.object);
        boxes.add(viper::checkBoxes(frame, objects, meshes));
      }
      const viper::ReprojectionCheck c = viper::checkReprojection(frame, meshes);
      if (per_frame) print(("frame " + std::to_string(frame.number) + ":").c_str(), c);
      all.add(c);
      coverage.add(frame, meshes);
      if (flow) {
        auto current = std::make_unique<FlowInput>(flowInput(frame));
        // (A pair whose frames differ in size, the window resized, has no flow: left out, counted.)
        const bool resized = previous && (previous->frame.width != frame.width || previous->frame.height != frame.height);
        if (resized) ++resized_pairs;
        if (previous && previous->frame.number + 1 == frame.number && !resized) {
          const viper::CaptureFrame& a = previous->frame;
          const viper::CaptureFrame& b = current->frame;
          const std::vector<int32_t> a_to_b = viper::associateDraws(a, previous->object_ids, b, current->object_ids);
          const viper::FlowField fwd = viper::computeFlow(a, b, a_to_b, current->depth_m, meshes);
          const viper::FlowField bwd = viper::computeFlow(
              b, a, viper::associateDraws(b, current->object_ids, a, previous->object_ids), previous->depth_m, meshes);
          const viper::FlowConsistencyCheck fc = viper::checkFlowPair(a, b, fwd, bwd);
          if (per_frame) printFlow(fc, 1);
          flow_all.add(fc);
          static_all.add(viper::checkStaticFlow(a, b, a_to_b, fwd));
          ++pairs;
        }
        previous = std::move(current);
      }
      if (max_frames && ++checked_frames >= max_frames) break;
      if (!max_frames) ++checked_frames;
    }
  } catch (const std::exception& e) {
    std::cerr << "capture_check: " << e.what() << "\n";
    status = 1;
  }
  print(("all " + std::to_string(checked_frames) + " frames:").c_str(), all);
  if (resized_pairs)
    std::printf("flow: %llu pairs of consecutive frames of different sizes (the window resized) left out\n",
                static_cast<unsigned long long>(resized_pairs));
  printGaps(coverage.gaps);
  if (flow) {
    printFlow(flow_all, pairs);
    std::printf("static surfaces (%.1f%% of id pixels) against the camera's own motion: median %.2e p99 %.2e px\n",
                100.0 * static_all.static_pixels / (flow_all.id_pixels ? flow_all.id_pixels : 1),
                viper::quantile(static_all.error_px, 0.5), viper::quantile(static_all.error_px, 0.99));
  }
  if (pipeline) {
    tracks.print(checked_frames);
    std::printf("boxes: %llu object-frames; of their %llu pixels' points (depth), outside their box by (relative to "
                "distance) p99 %.2e p99.9 %.2e max %.2e\n",
                static_cast<unsigned long long>(boxes.objects), static_cast<unsigned long long>(boxes.pixels),
                viper::quantile(boxes.outside_relative, 0.99), viper::quantile(boxes.outside_relative, 0.999),
                viper::quantile(boxes.outside_relative, 1.0));
  }
  Verdicts verdicts;
  judgeReprojection(verdicts, all, coverage);
  if (flow) judgeFlow(verdicts, flow_all, static_all, pairs);
  else verdicts.notAsked("flow forward-backward, photometric, static surfaces", "--flow");
  if (!pipeline) {
    verdicts.notAsked("boxes", "--labels");
  } else if (boxes.outside_relative.empty()) {
    verdicts.notRun("boxes", "no object with a box has pixels with depth and a camera");
  } else {
    const float p999 = viper::quantile(boxes.outside_relative, 0.999);
    verdicts.judge("boxes", p999 <= kBoxesOutsideP999, format("p99.9 %.2e of the distance outside", p999),
                   "p99.9 <= 1e-3");
  }
  const int judged = verdicts.finish();
  return status ? status : judged;
}
