#include "viper/ground_truth/flow_step.h"

#include "viper/ground_truth/ego_motion.h"
#include "viper/ground_truth/scene_flow.h"

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <future>
#include <limits>
#include <stdexcept>

namespace viper {
namespace {

// Draw indices 0..n-1 in order, deformed positions in fours, every draw id naming a draw.
std::string drawsProblem(const CaptureFrame& f, const uint32_t* draw_ids) {
  for (size_t i = 0; i < f.draws.size(); ++i) {
    if (f.draws[i].index != i)
      return "draw " + std::to_string(i) + " has index " + std::to_string(f.draws[i].index) + " (0..n-1 expected)";
    if (f.draws[i].deformed_clip_xyzw.size() % 4 != 0)
      return "draw " + std::to_string(i) + " has " + std::to_string(f.draws[i].deformed_clip_xyzw.size()) +
             " deformed_clip_xyzw floats, not a multiple of 4";
  }
  // The largest id first; the culprit only where there is one.
  const size_t n = f.pixelCount();
  if (largestDrawId(draw_ids, n) <= f.draws.size()) return {};
  const size_t p = static_cast<size_t>(std::find_if(draw_ids, draw_ids + n, [&](uint32_t id) {
                                         return id > f.draws.size();
                                       }) - draw_ids);
  return "draw id " + std::to_string(draw_ids[p]) + " at pixel " + std::to_string(p) + " in draw_ids, but only " +
         std::to_string(f.draws.size()) + " draws";
}

std::string frameText(unsigned long number) { return " (frame " + std::to_string(number) + "): "; }

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char text[512];
  std::snprintf(text, sizeof text, fmt, args...);
  return text;
}

// CPU time of the calling thread, nanoseconds.
int64_t threadCpuNs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec;
}

}  // namespace

FlowStep::FlowStep(const FlowSettings& settings) : settings_(settings) {}

FlowStep::HeldPtr FlowStep::makeHeldFrame(const GroundTruthInputPtr& input, const std::optional<FrameCamera>& camera,
                                          const std::vector<TrackedObject>& objects, StepProblems& problems) {
  const CaptureFrame& f = input->frame;
  const unsigned long number = f.number;
  std::string problem = drawsProblem(f, input->draw_ids);
  if (!problem.empty()) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "draws", frameText(number) + problem + "; frame dropped"});
    return nullptr;
  }
  auto held = std::make_shared<HeldFrame>();
  held->input = input;
  // computeFlow reads the metres where they are (FlowFramePixels): no window depth is made.
  if (camera) held->camera_projection = camera->projection;
  held->pixels.width = f.width, held->pixels.height = f.height, held->pixels.draws = &f.draws;
  held->pixels.draw_ids = input->draw_ids;
  held->pixels.primitive_ids = input->primitive_ids;
  held->pixels.depth_metres = input->depth_m;
  held->pixels.depth_projection = held->camera_projection ? &*held->camera_projection : nullptr;
  if (camera) {
    try {
      egoPoseFromView(camera->view, 0.0);  // throws unless the view matrix is rigid
      held->optical_from_world = opticalFromWorld(camera->view);
      held->camera_view = camera->view;
    } catch (const std::exception& e) {
      problems.push_back({StepInput::kDraws, StepSeverity::kWarning, "view",
                          frameText(number) + "camera view matrix: " + e.what() + "; no relative pose for this frame"});
    }
  }

  // Per draw: the track id of its object. Visible placed draws in no object have no association.
  held->object_ids.assign(f.draws.size(), 0);
  std::vector<bool> listed(f.draws.size(), false);
  size_t out_of_range = 0;
  for (const TrackedObject& o : objects) {
    for (uint32_t d : o.object.draws) {
      if (d >= f.draws.size()) {
        ++out_of_range;
        continue;
      }
      listed[d] = true;
      held->object_ids[d] = std::max(o.track_id, 0);
    }
  }
  held->excluded.assign(f.draws.size(), false);
  size_t unlisted = 0, unlisted_pixels = 0;
  for (size_t i = 0; i < f.draws.size(); ++i) {
    const DrawRecord& d = f.draws[i];
    if (!listed[i] && (d.matrix_flags & kHasWorld) && d.visible_pixels > 0) {
      held->excluded[i] = true;
      ++unlisted;
      unlisted_pixels += d.visible_pixels;
    }
  }
  if (out_of_range > 0 || unlisted > 0)
    problems.push_back({StepInput::kObjects, StepSeverity::kError, "association",
                        format(" (frame %lu): %zu visible draws (%zu pixels) are in no object and %zu object parts "
                               "name no draw of the frame's %zu: those pixels have no association, no flow",
                               number, unlisted, unlisted_pixels, out_of_range, f.draws.size())});
  return held;
}

bool FlowStep::flowBetween(const HeldFrame& a, const HeldFrame& b, const MeshRegistry& meshes, FlowBuffers buffers,
                           StepProblems& problems, float* scene_xyzd) {
  std::vector<int32_t> a_to_b = associateDraws(a.frame(), a.object_ids, b.frame(), b.object_ids);
  for (size_t i = 0; i < a_to_b.size(); ++i) {
    int32_t& j = a_to_b[i];
    if (a.excluded[i] || (j >= 0 && b.excluded[j])) j = -1;
    if (j < 0) continue;
    const DrawRecord& da = a.frame().draws[i];
    const DrawRecord& db = b.frame().draws[j];
    if (da.visible_pixels == 0 || (da.deformed_clip_xyzw.empty() && db.deformed_clip_xyzw.empty())) continue;
    const MeshRecord* mesh = meshes.find(da.mesh_key);
    const size_t floats = mesh ? 4 * (mesh->positions_xyz.size() / 3) : 0;
    if (!mesh) {
      problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "missing_mesh",
                          format(": mesh %016llx of deformed draw %zu (frame %lu) is not in the mesh store; its "
                                 "pixels have no flow", static_cast<unsigned long long>(da.mesh_key), i,
                                 static_cast<unsigned long>(a.frame().number))});
    } else if (da.deformed_clip_xyzw.size() != floats || db.deformed_clip_xyzw.size() != floats) {
      problems.push_back({StepInput::kDraws, StepSeverity::kError, "deformed",
                          format(": deformed draw %zu (mesh %016llx, %zu vertices) has %zu vertex positions in frame "
                                 "%lu and its draw %d has %zu in frame %lu: missing vertex positions, its pixels "
                                 "have no flow", i, static_cast<unsigned long long>(da.mesh_key), floats / 4,
                                 da.deformed_clip_xyzw.size() / 4, static_cast<unsigned long>(a.frame().number), j,
                                 db.deformed_clip_xyzw.size() / 4, static_cast<unsigned long>(b.frame().number))});
    }
  }
  FlowStats stats;
  computeFlow(a.pixels, b.pixels, a_to_b, b.input->depth_m, meshes, buffers.uv, buffers.visible, settings_.options,
              &stats);
  // The first flow out of a frame reports its pixels without depth (the same in every flow from it).
  if (stats.no_depth > 0 && !a.depth_reported.exchange(true))
    problems.push_back({StepInput::kDepth, StepSeverity::kError, "bad_depth",
                        format(" (frame %lu): %zu pixels of a draw have no finite positive depth (or no projection); "
                               "their flow is undefined", static_cast<unsigned long>(a.frame().number), stats.no_depth)});
  if (!scene_xyzd) return true;
  if (!a.camera_view || !b.camera_view) {
    std::fill(scene_xyzd, scene_xyzd + kSceneFlowChannels * a.frame().pixelCount(),
              std::numeric_limits<float>::quiet_NaN());
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "scene_flow",
                        format(" (frame %lu -> %lu): no usable camera view in %s: no scene flow",
                               static_cast<unsigned long>(a.frame().number), static_cast<unsigned long>(b.frame().number),
                               a.camera_view ? "the second" : "the first")});
    return false;
  }
  computeSceneFlow(a.pixels, b.pixels, a_to_b, meshes, opticalMotion(*a.camera_view, *b.camera_view), buffers.uv,
                   scene_xyzd);
  return true;
}

// Forward on this thread, backward on another, side by side: the frame's flow is ready in about half
// the time where a core is free (the same CPU either way). computeFlow reads only its inputs and
// writes only its outputs; the buffers come from the sink here, on this thread. The future of
// std::async waits for the helper in its destructor, also when the forward flow throws.
void FlowStep::bothWays(const HeldFrame& prev, const HeldFrame& cur, const MeshRegistry& meshes, FlowSink& sink,
                        StepProblems& problems, bool want_scene, bool& scene_done) {
  const FlowBuffers forward = sink.take(FlowKind::kForward, *prev.input);
  const FlowBuffers backward = sink.take(FlowKind::kBackward, *cur.input);
  float* const scene = want_scene ? sink.takeSceneFlow(*prev.input) : nullptr;
  StepProblems backward_problems;
  std::future<void> done = std::async(std::launch::async, [&] {
    const int64_t start = threadCpuNs();
    flowBetween(cur, prev, meshes, backward, backward_problems);
    helper_cpu_ns_ = threadCpuNs() - start;
  });
  scene_done = flowBetween(prev, cur, meshes, forward, problems, scene) && scene;
  done.get();  // its exception, if any
  problems.insert(problems.end(), backward_problems.begin(), backward_problems.end());
}

bool FlowStep::inOrder(const FrameStamp& stamp, uint64_t number, StepProblems& problems) const {
  if (window_.empty() || window_.back()->input->stamp < stamp) return true;
  problems.push_back({StepInput::kDraws, StepSeverity::kError, "stamp_order",
                      format(": frame %lu stamp %.6f is not after the previous frame's %.6f; frame dropped",
                             static_cast<unsigned long>(number), stamp.seconds(),
                             window_.back()->input->stamp.seconds())});
  return false;
}

bool FlowStep::process(const GroundTruthInputPtr& input, const std::optional<FrameCamera>& camera,
                       const std::vector<TrackedObject>& objects, const MeshRegistry& meshes, const Want& want,
                       FlowSink& sink, Output& out, StepProblems& problems) {
  out = Output();
  helper_cpu_ns_ = 0;
  const unsigned long number = input->frame.number;
  if (!inOrder(input->stamp, number, problems)) return false;
  HeldPtr cur;
  if (input->draw_ids && input->depth_m && input->primitive_ids) {
    try {
      cur = makeHeldFrame(input, camera, objects, problems);
    } catch (const std::exception& e) {
      problems.push_back({StepInput::kDraws, StepSeverity::kError, "frame", frameText(number) + e.what() + "; frame dropped"});
    }
  }
  if (!cur) {
    window_.clear();  // the sequence is broken: no flow spans the dropped frame
    return false;
  }
  if (!window_.empty()) {
    const CaptureFrame& c = cur->frame();
    const CaptureFrame& p = window_.back()->frame();
    if (c.width != p.width || c.height != p.height) {
      problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "size_change",
                          format(" (frame %lu): %ux%u, but the previous frame was %ux%u; the window starts over",
                                 number, c.width, c.height, p.width, p.height)});
      window_.clear();
    } else if (c.number <= p.number) {
      // A looping replay, or another capture: no flow across it, and nothing was lost.
      problems.push_back({StepInput::kDraws, StepSeverity::kInfo, "numbers_restart",
                          format(": frame %lu follows frame %lu: the frame numbers start over (a loop or another "
                                 "capture); the window starts over", number, static_cast<unsigned long>(p.number))});
      window_.clear();
    } else if (c.number != p.number + 1) {
      // The warning is throttled: the running count says how many were lost in between.
      const uint64_t lost = c.number - p.number - 1;
      frames_lost_ += lost;
      problems.push_back({StepInput::kDraws, StepSeverity::kWarning, "gap",
                          format(": frame %lu follows frame %lu: %lu %s between dropped (%lu dropped so far); no flow "
                                 "spans them, the window starts over", number, static_cast<unsigned long>(p.number),
                                 static_cast<unsigned long>(lost), lost == 1 ? "frame" : "frames",
                                 static_cast<unsigned long>(frames_lost_))});
      window_.clear();
    }
  }
  window_.push_back(cur);
  while (window_.size() > settings_.window_size) {
    window_.pop_front();
  }

  try {
    const size_t n = window_.size();
    if (n >= 2) {
      const HeldFrame& prev = *window_[n - 2];
      out.forward_from = prev.input->stamp;
      const bool forward = want.forward || want.scene_flow;  // the scene flow needs the forward flow
      if (forward && want.backward) {
        bothWays(prev, *cur, meshes, sink, problems, want.scene_flow, out.scene_flow);
        out.forward = out.backward = true;
      } else {
        if (forward) {
          const FlowBuffers buffers = sink.take(FlowKind::kForward, *prev.input);
          float* const scene = want.scene_flow ? sink.takeSceneFlow(*prev.input) : nullptr;
          out.scene_flow = flowBetween(prev, *cur, meshes, buffers, problems, scene) && scene;
          out.forward = true;
        }
        if (want.backward) {
          flowBetween(*cur, prev, meshes, sink.take(FlowKind::kBackward, *cur->input), problems);
          out.backward = true;
        }
      }
    }
    const size_t k = static_cast<size_t>(settings_.wide_baseline);
    if (k > 0 && n > k && want.wide) {
      const HeldFrame& a = *window_[n - 1 - k];
      flowBetween(a, *cur, meshes, sink.take(FlowKind::kWide, *a.input), problems);
      out.wide = true;
      out.wide_from = a.input->stamp;
    }
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "flow",
                        frameText(number) + e.what() + "; no flow for this frame"});
    out = Output();
    return false;
  }
  return true;
}

FlowStep::HeldPtr FlowStep::find(const FrameStamp& stamp) const {
  for (const HeldPtr& f : window_)
    if (f->input->stamp == stamp) return f;
  return nullptr;
}

const GroundTruthInput* FlowStep::held(const FrameStamp& stamp) const {
  const HeldPtr f = find(stamp);
  return f ? f->input.get() : nullptr;
}

std::string FlowStep::heldStamps() const {
  std::string held;
  for (const HeldPtr& f : window_) held += (held.empty() ? "" : ", ") + std::to_string(f->input->stamp.seconds());
  return held;
}

void FlowStep::flowBetween(const FrameStamp& a, const FrameStamp& b, const MeshRegistry& meshes, FlowBuffers buffers,
                           StepProblems& problems) {
  const HeldPtr fa = find(a), fb = find(b);
  if (!fa || !fb) throw std::invalid_argument("stamp " + std::to_string((fa ? b : a).seconds()) + " is not held");
  flowBetween(*fa, *fb, meshes, buffers, problems);
}

std::optional<Eigen::Isometry3d> FlowStep::relativePose(const FrameStamp& a, const FrameStamp& b) const {
  const HeldPtr fa = find(a), fb = find(b);
  if (!fa || !fb || !fa->optical_from_world || !fb->optical_from_world) return std::nullopt;
  return *fa->optical_from_world * fb->optical_from_world->inverse();
}

}  // namespace viper
