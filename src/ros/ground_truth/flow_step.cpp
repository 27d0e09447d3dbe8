#include "viper/ros/ground_truth/flow_step.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ros/bridge/cpu_meter.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cstdio>
#include <future>
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

}  // namespace

FlowStep::FlowStep(const FlowSettings& settings) : settings_(settings) {}

void FlowStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  meshes_.add(fromMeshStoreMsg(store, bad, &meshes_));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

FlowStep::HeldPtr FlowStep::makeHeldFrame(const DrawList& draws, const sensor_msgs::ImageConstPtr& depth,
                                          const sensor_msgs::ImageConstPtr& draw_ids,
                                          const sensor_msgs::ImageConstPtr& primitive_ids, const ObjectArray& objects,
                                          StepProblems& problems) {
  auto held = std::make_shared<HeldFrame>();
  CaptureFrame& f = held->frame;
  const unsigned long number = draws.frame_number;
  auto drop = [&](StepInput input, const char* kind, const std::string& problem) {
    problems.push_back({input, StepSeverity::kError, kind, frameText(number) + problem + "; frame dropped"});
    return nullptr;
  };
  // The images are read where they are (checkImage: packed rows, host byte order), and held.
  const uint32_t* ids = nullptr;
  std::string problem = frameFromDrawMsgs(draws, *draw_ids, f, ids);
  if (!problem.empty()) return drop(StepInput::kDrawIds, "draw_ids", problem);
  problem = drawsProblem(f, ids);
  if (!problem.empty()) return drop(StepInput::kDraws, "draws", problem);
  problem = checkImage(*depth, sensor_msgs::image_encodings::TYPE_32FC1, f.width, f.height);
  if (!problem.empty()) return drop(StepInput::kDepth, "depth", problem);
  problem = checkImage(*primitive_ids, sensor_msgs::image_encodings::TYPE_32SC1, f.width, f.height);
  if (!problem.empty()) return drop(StepInput::kPrimitiveIds, "primitive_ids", problem);
  held->header = draw_ids->header;
  held->depth = depth, held->draw_ids = draw_ids, held->primitive_ids = primitive_ids;
  held->depth_m = reinterpret_cast<const float*>(depth->data.data());

  // computeFlow reads the metres where they are (FlowFramePixels): no window depth is made.
  const std::optional<FrameCamera> camera = chooseFrameCamera(f);
  if (camera) held->camera_projection = camera->projection;
  held->pixels.width = f.width, held->pixels.height = f.height, held->pixels.draws = &f.draws;
  held->pixels.draw_ids = ids;
  held->pixels.primitive_ids = reinterpret_cast<const uint32_t*>(primitive_ids->data.data());
  held->pixels.depth_metres = held->depth_m;
  held->pixels.depth_projection = held->camera_projection ? &*held->camera_projection : nullptr;
  if (camera) {
    try {
      egoPoseFromView(camera->view, 0.0);  // throws unless the view matrix is rigid
      held->optical_from_world = opticalFromWorld(camera->view);
    } catch (const std::exception& e) {
      problems.push_back({StepInput::kDraws, StepSeverity::kWarning, "view",
                          frameText(number) + "camera view matrix: " + e.what() + "; no relative pose for this frame"});
    }
  }

  // Per draw: the track id of its object. Visible placed draws in no object have no association.
  held->object_ids.assign(f.draws.size(), 0);
  std::vector<bool> listed(f.draws.size(), false);
  size_t out_of_range = 0;
  for (const Object& o : objects.objects) {
    for (uint32_t d : o.draws) {
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

void FlowStep::flowBetween(const HeldFrame& a, const HeldFrame& b, float* uv, uint8_t* visible,
                           StepProblems& problems) {
  std::vector<int32_t> a_to_b = associateDraws(a.frame, a.object_ids, b.frame, b.object_ids);
  for (size_t i = 0; i < a_to_b.size(); ++i) {
    int32_t& j = a_to_b[i];
    if (a.excluded[i] || (j >= 0 && b.excluded[j])) j = -1;
    if (j < 0) continue;
    const DrawRecord& da = a.frame.draws[i];
    const DrawRecord& db = b.frame.draws[j];
    if (da.visible_pixels == 0 || (da.deformed_clip_xyzw.empty() && db.deformed_clip_xyzw.empty())) continue;
    const MeshRecord* mesh = meshes_.find(da.mesh_key);
    const size_t floats = mesh ? 4 * (mesh->positions_xyz.size() / 3) : 0;
    if (!mesh) {
      problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "missing_mesh",
                          format(": mesh %016llx of deformed draw %zu (frame %lu) is not in the mesh store; its "
                                 "pixels have no flow", static_cast<unsigned long long>(da.mesh_key), i,
                                 static_cast<unsigned long>(a.frame.number))});
    } else if (da.deformed_clip_xyzw.size() != floats || db.deformed_clip_xyzw.size() != floats) {
      problems.push_back({StepInput::kDraws, StepSeverity::kError, "deformed",
                          format(": deformed draw %zu (mesh %016llx, %zu vertices) has %zu vertex positions in frame "
                                 "%lu and its draw %d has %zu in frame %lu: missing vertex positions, its pixels "
                                 "have no flow", i, static_cast<unsigned long long>(da.mesh_key), floats / 4,
                                 da.deformed_clip_xyzw.size() / 4, static_cast<unsigned long>(a.frame.number), j,
                                 db.deformed_clip_xyzw.size() / 4, static_cast<unsigned long>(b.frame.number))});
    }
  }
  FlowStats stats;
  computeFlow(a.pixels, b.pixels, a_to_b, b.depth_m, meshes_, uv, visible, settings_.options, &stats);
  // The first flow out of a frame reports its pixels without depth (the same in every flow from it).
  if (stats.no_depth > 0 && !a.depth_reported.exchange(true))
    problems.push_back({StepInput::kDepth, StepSeverity::kError, "bad_depth",
                        format(" (frame %lu): %zu pixels of a draw have no finite positive depth (or no projection); "
                               "their flow is undefined", static_cast<unsigned long>(a.frame.number), stats.no_depth)});
}

FlowMessages FlowStep::takeMessages(const HeldFrame& a) {
  // computeFlow writes every pixel: a recycled message needs no clearing.
  const uint32_t w = a.frame.width, h = a.frame.height;
  return FlowMessages{flow_pool_.take(a.header, w, h, sensor_msgs::image_encodings::TYPE_32FC2, 8),
                      visible_pool_.take(a.header, w, h, sensor_msgs::image_encodings::MONO8, 1)};
}

void FlowStep::flowBetween(const HeldFrame& a, const HeldFrame& b, FlowMessages& m, StepProblems& problems) {
  flowBetween(a, b, reinterpret_cast<float*>(m.flow->data.data()), m.visible->data.data(), problems);
}

FlowMessages FlowStep::flowBetween(const HeldFrame& a, const HeldFrame& b, StepProblems& problems) {
  FlowMessages m = takeMessages(a);
  flowBetween(a, b, m, problems);
  return m;
}

// Forward on this thread, backward on another, side by side: the frame's flow is ready in about half
// the time where a core is free (the same CPU either way). computeFlow reads only its inputs and
// writes only its outputs; the messages come from the pools here, on this thread. The future of
// std::async waits for the helper in its destructor, also when the forward flow throws.
void FlowStep::bothWays(const HeldFrame& prev, const HeldFrame& cur, Output& out, StepProblems& problems) {
  FlowMessages forward = takeMessages(prev), backward = takeMessages(cur);
  StepProblems backward_problems;
  std::future<void> done = std::async(std::launch::async, [&] {
    const int64_t start = CpuMeter::threadCpuNs();
    flowBetween(cur, prev, backward, backward_problems);
    helper_cpu_ns_ = CpuMeter::threadCpuNs() - start;
  });
  flowBetween(prev, cur, forward, problems);
  done.get();  // its exception, if any
  problems.insert(problems.end(), backward_problems.begin(), backward_problems.end());
  out.forward = std::move(forward);
  out.backward = std::move(backward);
}

bool FlowStep::process(const DrawList& draws, const sensor_msgs::ImageConstPtr& depth,
                       const sensor_msgs::ImageConstPtr& draw_ids, const sensor_msgs::ImageConstPtr& primitive_ids,
                       const ObjectArray& objects, const Want& want, Output& out, StepProblems& problems) {
  out = Output();
  helper_cpu_ns_ = 0;
  const unsigned long number = draws.frame_number;
  if (!window_.empty() && draws.header.stamp <= window_.back()->header.stamp) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "stamp_order",
                        format(": frame %lu stamp %.6f is not after the previous frame's %.6f; frame dropped", number,
                               draws.header.stamp.toSec(), window_.back()->header.stamp.toSec())});
    return false;
  }
  HeldPtr cur;
  try {
    cur = makeHeldFrame(draws, depth, draw_ids, primitive_ids, objects, problems);
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "frame", frameText(number) + e.what() + "; frame dropped"});
  }
  if (!cur) {
    window_.clear();  // the sequence is broken: no flow spans the dropped frame
    return false;
  }
  if (!window_.empty()) {
    const HeldFrame& prev = *window_.back();
    if (cur->frame.width != prev.frame.width || cur->frame.height != prev.frame.height) {
      problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "size_change",
                          format(" (frame %lu): %ux%u, but the previous frame was %ux%u; the window starts over",
                                 number, cur->frame.width, cur->frame.height, prev.frame.width, prev.frame.height)});
      window_.clear();
    } else if (cur->frame.number <= prev.frame.number) {
      // A looping replay, or another capture: no flow across it, and nothing was lost.
      problems.push_back({StepInput::kDraws, StepSeverity::kInfo, "numbers_restart",
                          format(": frame %lu follows frame %lu: the frame numbers start over (a loop or another "
                                 "capture); the window starts over", number,
                                 static_cast<unsigned long>(prev.frame.number))});
      window_.clear();
    } else if (cur->frame.number != prev.frame.number + 1) {
      // The warning is throttled: the running count says how many were lost in between.
      const uint64_t lost = cur->frame.number - prev.frame.number - 1;
      frames_lost_ += lost;
      problems.push_back({StepInput::kDraws, StepSeverity::kWarning, "gap",
                          format(": frame %lu follows frame %lu: %lu %s between dropped (%lu dropped so far); no flow "
                                 "spans them, the window starts over", number,
                                 static_cast<unsigned long>(prev.frame.number), static_cast<unsigned long>(lost),
                                 lost == 1 ? "frame" : "frames", static_cast<unsigned long>(frames_lost_))});
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
      if (want.forward && want.backward) {
        bothWays(prev, *cur, out, problems);
      } else {
        if (want.forward) out.forward = flowBetween(prev, *cur, problems);
        if (want.backward) out.backward = flowBetween(*cur, prev, problems);
      }
    }
    const size_t k = static_cast<size_t>(settings_.wide_baseline);
    if (k > 0 && n > k && want.wide) {
      const HeldFrame& a = *window_[n - 1 - k];
      out.wide = flowBetween(a, *cur, problems);
    }
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "flow",
                        frameText(number) + e.what() + "; no flow for this frame"});
    out = Output();
    return false;
  }
  return true;
}

void FlowStep::correspondences(const ros::Time& stamp_a, const ros::Time& stamp_b, Correspondences::Response& res,
                               StepProblems& problems) {
  HeldPtr a, b;
  std::string held;
  for (const HeldPtr& f : window_) {
    if (f->header.stamp == stamp_a) a = f;
    if (f->header.stamp == stamp_b) b = f;
    held += (held.empty() ? "" : ", ") + std::to_string(f->header.stamp.toSec());
  }
  if (!a || !b) {
    res.success = false;
    res.message = std::string("stamp ") + (a ? "b " + std::to_string(stamp_b.toSec()) : "a " + std::to_string(stamp_a.toSec())) +
                  " is not held; held: [" + held + "]";
    return;
  }
  try {
    shapeFlowMsgs(a->frame.width, a->frame.height, a->header, res.flow, res.visible);
    flowBetween(*a, *b, reinterpret_cast<float*>(res.flow.data.data()), res.visible.data.data(), problems);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    return;
  }
  res.pose_valid = a->optical_from_world && b->optical_from_world;
  if (res.pose_valid) res.b_in_a = toTransformMsg(*a->optical_from_world * b->optical_from_world->inverse());
  res.success = true;
}

}  // namespace viper
