// capture_check: how much of a capture's scene has ids, matrices and meshes, and how well they agree
// with its depth image (viper::checkReprojection), for captures of programs without an oracle.
// Exit code 0 = read to the end, 1 = damaged (figures up to the damage printed), 2 = usage/open error.
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/instance_pipeline.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>

namespace {

int usage(int code = 2) {
  std::cerr << "usage: capture_check FILE.vcap [--from N] [--frames N] [--per-frame] [--flow] [--labels L.yaml]\n"
               "                     [--resume-tracks]\n"
               "  For every pixel with a draw id: projects the triangle its draw and primitive id name with\n"
               "  the recorded matrices (or post-vertex-shader positions) and prints how far the pixel lies\n"
               "  from it (px) and how far its depth is from the triangle's (relative), with the fractions\n"
               "  of scene pixels that have an id and a placed mesh, and what the layer reported it could not\n"
               "  record (draws without ids, matrices or mesh; draws not recorded). --from N skips frames\n"
               "  numbered below N.\n"
               "  --flow: also the flow of each pair of consecutive frames both ways (viper::computeFlow, draws\n"
               "  associated by mesh and placement): forward-backward endpoint error and the photometric error\n"
               "  of warping the next frame by the flow, against no motion; and static surfaces (same mesh,\n"
               "  same world) against the flow the camera's own motion gives from depth (viper::checkStaticFlow).\n"
               "  --labels: also the instances pipeline with that label table: share of id pixels with a class,\n"
               "  per thing class its tracks (how many, frames each: ids stable over time), and every object's\n"
               "  pixels (their depth) against its 3D box (viper::checkBoxes); --resume-tracks:\n"
               "  the tracker's resume_by_resources (an object back after a long gap takes up its own id).\n";
  return code;
}

void print(const char* label, const viper::ReprojectionCheck& c) {
  const double scene = c.scene_pixels ? static_cast<double>(c.scene_pixels) : 1.0;
  size_t within_half = 0;
  for (float d : c.distance_px) within_half += d <= 0.5f;
  std::printf("%s scene %5.1f%% of pixels | id %5.1f%% | placed %5.1f%% | checked %llu px: distance median %.3f "
              "p99 %.3f px, <= 0.5 px %.2f%% | depth rel. median %.2e p99 %.2e\n",
              label, 100.0 * c.scene_pixels / (c.pixels ? c.pixels : 1), 100.0 * c.id_pixels / scene,
              100.0 * c.placed_pixels / scene, static_cast<unsigned long long>(c.checked_pixels),
              viper::quantile(c.distance_px, 0.5), viper::quantile(c.distance_px, 0.99),
              c.distance_px.empty() ? 0.0 : 100.0 * within_half / c.distance_px.size(),
              viper::quantile(c.depth_relative, 0.5), viper::quantile(c.depth_relative, 0.99));
}

void printGaps(const viper::CaptureGaps& g) {
  std::printf("gaps the layer reported: of %llu recorded draws, %llu without ids (shader not rewritten), %llu missing "
              "a matrix the profile names (%llu px), %llu without mesh (%llu px); %llu draws into the scene not "
              "recorded (no program, or a multi-draw reading gl_DrawID)\n",
              static_cast<unsigned long long>(g.draws), static_cast<unsigned long long>(g.no_ids),
              static_cast<unsigned long long>(g.matrix_missing), static_cast<unsigned long long>(g.matrix_missing_pixels),
              static_cast<unsigned long long>(g.no_mesh), static_cast<unsigned long long>(g.no_mesh_pixels),
              static_cast<unsigned long long>(g.unrecorded_draws));
}

void printFlow(const viper::FlowConsistencyCheck& c, uint64_t pairs) {
  size_t within = 0;
  for (float d : c.forward_backward_px) within += d <= 0.5f;
  std::printf("flow of %llu pairs: defined on %5.1f%% of id pixels, visible in the next frame %5.1f%% | "
              "forward-backward median %.2e p99 %.2e px, <= 0.5 px %.2f%% | photometric error %.2f "
              "(no motion: %.2f) of 255\n",
              static_cast<unsigned long long>(pairs), 100.0 * c.flow_pixels / (c.id_pixels ? c.id_pixels : 1),
              100.0 * c.visible_pixels / (c.flow_pixels ? c.flow_pixels : 1), viper::quantile(c.forward_backward_px, 0.5),
              viper::quantile(c.forward_backward_px, 0.99),
              c.forward_backward_px.empty() ? 0.0 : 100.0 * within / c.forward_backward_px.size(), c.photometricFlow(),
              c.photometricZero());
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
  std::string path;
  uint64_t from = 0, max_frames = 0;
  bool per_frame = false, flow = false, resume = false;
  std::string labels;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage(0);
    if (a == "--from" && i + 1 < argc) from = std::strtoull(argv[++i], nullptr, 10);
    else if (a == "--frames" && i + 1 < argc) max_frames = std::strtoull(argv[++i], nullptr, 10);
    else if (a == "--per-frame") per_frame = true;
    else if (a == "--flow") flow = true;
    else if (a == "--resume-tracks") resume = true;
    else if (a == "--labels" && i + 1 < argc) labels = argv[++i];
    else if (a.rfind("--", 0) == 0 || !path.empty()) return usage();
    else path = a;
  }
  if (path.empty()) return usage();
  std::unique_ptr<viper::CaptureReader> reader;
  try {
    reader = std::make_unique<viper::CaptureReader>(path);
  } catch (const std::exception& e) {
    std::cerr << "capture_check: " << e.what() << "\n";
    return 2;
  }
  viper::MeshRegistry meshes;
  viper::ReprojectionCheck all;
  viper::CaptureGaps gaps;
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
      gaps.add(frame);
      if (flow) {
        auto current = std::make_unique<FlowInput>(flowInput(frame));
        if (previous && previous->frame.number + 1 == frame.number) {
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
  printGaps(gaps);
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
  return status;
}
