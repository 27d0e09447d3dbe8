#include "viper/ros/ground_truth/flow.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace viper {
namespace {

// Draw indices 0..n-1 in order, deformed positions in fours, every draw id naming a draw.
std::string drawsProblem(const CaptureFrame& f) {
  for (size_t i = 0; i < f.draws.size(); ++i) {
    if (f.draws[i].index != i)
      return "draw " + std::to_string(i) + " has index " + std::to_string(f.draws[i].index) + " (0..n-1 expected)";
    if (f.draws[i].deformed_clip_xyzw.size() % 4 != 0)
      return "draw " + std::to_string(i) + " has " + std::to_string(f.draws[i].deformed_clip_xyzw.size()) +
             " deformed_clip_xyzw floats, not a multiple of 4";
  }
  for (uint32_t id : f.draw_ids) {
    if (id > f.draws.size())
      return "draw id " + std::to_string(id) + " in draw_ids, but only " + std::to_string(f.draws.size()) + " draws";
  }
  return {};
}

}  // namespace

Flow::Flow(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), private_nh_(pnh), it_(nh) {}

bool Flow::start() {
  const std::string me = private_nh_.getNamespace();
  private_nh_.param("wide_baseline", wide_baseline_, 0);
  if (wide_baseline_ < 0) {
    ROS_ERROR("%s: ~wide_baseline must be >= 0 frames (got %d); using 0 (off)", me.c_str(), wide_baseline_);
    wide_baseline_ = 0;
  }
  int window = 5;
  private_nh_.param("window_size", window, 5);
  if (window < 2 || window < wide_baseline_ + 1) {
    const int fixed = std::max(std::max(2, wide_baseline_ + 1), window);
    ROS_ERROR("%s: ~window_size must be >= 2 and >= ~wide_baseline + 1 (got %d, wide_baseline %d); using %d",
              me.c_str(), window, wide_baseline_, fixed);
    window = fixed;
  }
  window_size_ = static_cast<size_t>(window);
  private_nh_.param("occlusion_relative", options_.occlusion_relative, options_.occlusion_relative);
  private_nh_.param("occlusion_absolute_m", options_.occlusion_absolute_m, options_.occlusion_absolute_m);
  if (!(options_.occlusion_relative >= 0.0 && options_.occlusion_relative < 1.0) ||
      !(options_.occlusion_absolute_m >= 0.0)) {
    ROS_ERROR("%s: ~occlusion_relative must be in [0, 1) and ~occlusion_absolute_m >= 0 (got %g, %g); using 0.005, "
              "0.02", me.c_str(), options_.occlusion_relative, options_.occlusion_absolute_m);
    options_ = FlowOptions();
  }
  int queue_size = 10;
  private_nh_.param("queue_size", queue_size, 10);
  if (queue_size < 1) {
    ROS_ERROR("%s: ~queue_size must be >= 1 (got %d); using 10", me.c_str(), queue_size);
    queue_size = 10;
  }

  forward_pub_ = it_.advertise("flow/forward", queue_size);
  forward_visible_pub_ = it_.advertise("flow/forward_visible", queue_size);
  backward_pub_ = it_.advertise("flow/backward", queue_size);
  backward_visible_pub_ = it_.advertise("flow/backward_visible", queue_size);
  if (wide_baseline_ > 0) {
    wide_pub_ = it_.advertise("flow/wide", queue_size);
    wide_visible_pub_ = it_.advertise("flow/wide_visible", queue_size);
  }
  correspondences_srv_ = private_nh_.advertiseService("correspondences", &Flow::onCorrespondences, this);
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Flow::onMeshStore, this);
  const image_transport::TransportHints raw("raw");
  draws_sub_.subscribe(nh_, "draws", queue_size);
  depth_sub_.subscribe(it_, "depth", queue_size, raw);
  draw_ids_sub_.subscribe(it_, "draw_ids", queue_size, raw);
  primitive_ids_sub_.subscribe(it_, "primitive_ids", queue_size, raw);
  objects_sub_.subscribe(nh_, "objects", queue_size);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(
      SyncPolicy(queue_size), draws_sub_, depth_sub_, draw_ids_sub_, primitive_ids_sub_, objects_sub_);
  sync_->registerCallback(&Flow::onFrame, this);
  sync_->registerDropCallback(&Flow::onDrop, this);
  return true;
}

void Flow::onMeshStore(const MeshStore::ConstPtr& store) {
  std::vector<std::string> problems;
  std::vector<MeshRecord> meshes = fromMeshStoreMsg(*store, problems);
  for (const std::string& p : problems) ROS_ERROR_THROTTLE(5, "%s: %s", mesh_store_sub_.getTopic().c_str(), p.c_str());
  std::lock_guard<std::mutex> lock(mutex_);
  meshes_.add(meshes);
}

void Flow::onDrop(const DrawList::ConstPtr& draws, const ImageConstPtr& depth, const ImageConstPtr& draw_ids,
                  const ImageConstPtr& primitive_ids, const ObjectArray::ConstPtr& objects) {
  // The synchroniser gave up on a stamp: name the topics that never delivered it.
  std::string missing, stamp;
  auto note = [&](const auto& msg, const std::string& topic) {
    if (msg) {
      if (stamp.empty()) stamp = std::to_string(msg->header.stamp.toSec());
    } else {
      missing += (missing.empty() ? "" : ", ") + topic;
    }
  };
  note(draws, draws_sub_.getTopic());
  note(depth, depth_sub_.getTopic());
  note(draw_ids, draw_ids_sub_.getTopic());
  note(primitive_ids, primitive_ids_sub_.getTopic());
  note(objects, objects_sub_.getTopic());
  const std::string what = objects ? "" : " (no object list: the draws of this frame have no association)";
  ROS_ERROR_THROTTLE(5, "frame at stamp %s dropped: no message on %s%s; no flow spans it", stamp.c_str(),
                     missing.c_str(), what.c_str());
}

Flow::HeldPtr Flow::makeHeldFrame(const DrawList& draws, const sensor_msgs::Image& depth,
                                  const sensor_msgs::Image& draw_ids, const sensor_msgs::Image& primitive_ids,
                                  const ObjectArray& objects) {
  auto held = std::make_shared<HeldFrame>();
  CaptureFrame& f = held->frame;
  const unsigned long number = draws.frame_number;
  std::string problem = frameFromDrawMsgs(draws, draw_ids, f);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %s; frame dropped", draw_ids_sub_.getTopic().c_str(), number,
                       problem.c_str());
    return nullptr;
  }
  problem = drawsProblem(f);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %s; frame dropped", draws_sub_.getTopic().c_str(), number,
                       problem.c_str());
    return nullptr;
  }
  problem = depthFromImage(depth, f, held->depth_m);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %s; frame dropped", depth_sub_.getTopic().c_str(), number, problem.c_str());
    return nullptr;
  }
  problem = primitiveIdsFromImage(primitive_ids, f);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %s; frame dropped", primitive_ids_sub_.getTopic().c_str(), number,
                       problem.c_str());
    return nullptr;
  }
  held->header = draw_ids.header;

  const std::optional<FrameCamera> camera = chooseFrameCamera(f);
  size_t bad_depth = 0;
  f.depth_window = windowDepthFromMetres(f, held->depth_m, camera ? &camera->projection : nullptr, &bad_depth);
  if (bad_depth > 0)
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %zu pixels of a draw have no finite positive depth (or no projection); "
                       "their flow is undefined", depth_sub_.getTopic().c_str(), number, bad_depth);
  if (camera) {
    try {
      egoPoseFromView(camera->view, 0.0);  // throws unless the view matrix is rigid
      held->optical_from_world = opticalFromWorld(camera->view);
    } catch (const std::exception& e) {
      ROS_WARN_THROTTLE(5, "%s (frame %lu): camera view matrix: %s; no relative pose for this frame",
                        draws_sub_.getTopic().c_str(), number, e.what());
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
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %zu visible draws (%zu pixels) are in no object and %zu object parts name "
                       "no draw of the frame's %zu: those pixels have no association, no flow",
                       objects_sub_.getTopic().c_str(), number, unlisted, unlisted_pixels, out_of_range,
                       f.draws.size());
  return held;
}

void Flow::flowBetween(const HeldFrame& a, const HeldFrame& b, FlowField& out) {
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
      ROS_ERROR_THROTTLE(5, "%s: mesh %016llx of deformed draw %zu (frame %lu) is not in the mesh store; its pixels "
                         "have no flow", mesh_store_sub_.getTopic().c_str(),
                         static_cast<unsigned long long>(da.mesh_key), i, static_cast<unsigned long>(a.frame.number));
    } else if (da.deformed_clip_xyzw.size() != floats || db.deformed_clip_xyzw.size() != floats) {
      ROS_ERROR_THROTTLE(5, "%s: deformed draw %zu (mesh %016llx, %zu vertices) has %zu vertex positions in frame %lu "
                         "and its draw %d has %zu in frame %lu: missing vertex positions, its pixels have no flow",
                         draws_sub_.getTopic().c_str(), i, static_cast<unsigned long long>(da.mesh_key), floats / 4,
                         da.deformed_clip_xyzw.size() / 4, static_cast<unsigned long>(a.frame.number), j,
                         db.deformed_clip_xyzw.size() / 4, static_cast<unsigned long>(b.frame.number));
    }
  }
  computeFlow(a.frame, b.frame, a_to_b, b.depth_m, meshes_, out, options_);
}

void Flow::publish(const image_transport::Publisher& flow_pub, const image_transport::Publisher& visible_pub,
                   const std_msgs::Header& header, const FlowField& field) {
  const FlowMessages m = toFlowMsgs(field, header);
  flow_pub.publish(m.flow);
  visible_pub.publish(m.visible);
}

void Flow::onFrame(const DrawList::ConstPtr& draws, const ImageConstPtr& depth, const ImageConstPtr& draw_ids,
                   const ImageConstPtr& primitive_ids, const ObjectArray::ConstPtr& objects) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string& topic = draws_sub_.getTopic();
  const unsigned long number = draws->frame_number;
  if (!window_.empty() && draws->header.stamp <= window_.back()->header.stamp) {
    ROS_ERROR_THROTTLE(5, "%s: frame %lu stamp %.6f is not after the previous frame's %.6f; frame dropped",
                       topic.c_str(), number, draws->header.stamp.toSec(), window_.back()->header.stamp.toSec());
    return;
  }
  HeldPtr cur;
  try {
    cur = makeHeldFrame(*draws, *depth, *draw_ids, *primitive_ids, *objects);
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %s; frame dropped", topic.c_str(), number, e.what());
  }
  if (!cur) {
    window_.clear();  // the sequence is broken: no flow spans the dropped frame
    return;
  }
  if (!window_.empty()) {
    const HeldFrame& prev = *window_.back();
    if (cur->frame.width != prev.frame.width || cur->frame.height != prev.frame.height) {
      ROS_ERROR_THROTTLE(5, "%s (frame %lu): %ux%u, but the previous frame was %ux%u; the window starts over",
                         draw_ids_sub_.getTopic().c_str(), number, cur->frame.width, cur->frame.height,
                         prev.frame.width, prev.frame.height);
      window_.clear();
    } else if (cur->frame.number <= prev.frame.number) {
      // A looping replay, or another capture: no flow across it, and nothing was lost.
      ROS_INFO_THROTTLE(5, "%s: frame %lu follows frame %lu: the frame numbers start over (a loop or another "
                        "capture); the window starts over", topic.c_str(), number,
                        static_cast<unsigned long>(prev.frame.number));
      window_.clear();
    } else if (cur->frame.number != prev.frame.number + 1) {
      ROS_WARN_THROTTLE(5, "%s: frame %lu follows frame %lu: the frames between were dropped; the window starts over",
                        topic.c_str(), number, static_cast<unsigned long>(prev.frame.number));
      window_.clear();
    }
  }
  window_.push_back(cur);
  while (window_.size() > window_size_) window_.pop_front();

  try {
    const size_t n = window_.size();
    if (n >= 2) {
      const HeldFrame& prev = *window_[n - 2];
      if (forward_pub_.getNumSubscribers() > 0 || forward_visible_pub_.getNumSubscribers() > 0) {
        flowBetween(prev, *cur, scratch_);
        publish(forward_pub_, forward_visible_pub_, prev.header, scratch_);
      }
      if (backward_pub_.getNumSubscribers() > 0 || backward_visible_pub_.getNumSubscribers() > 0) {
        flowBetween(*cur, prev, scratch_);
        publish(backward_pub_, backward_visible_pub_, cur->header, scratch_);
      }
    }
    const size_t k = static_cast<size_t>(wide_baseline_);
    if (k > 0 && n > k && (wide_pub_.getNumSubscribers() > 0 || wide_visible_pub_.getNumSubscribers() > 0)) {
      const HeldFrame& a = *window_[n - 1 - k];
      flowBetween(a, *cur, scratch_);
      publish(wide_pub_, wide_visible_pub_, a.header, scratch_);
    }
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu): %s; no flow for this frame", topic.c_str(), number, e.what());
    return;
  }
  ++frames_;
}

bool Flow::onCorrespondences(Correspondences::Request& req, Correspondences::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  HeldPtr a, b;
  std::string held;
  for (const HeldPtr& f : window_) {
    if (f->header.stamp == req.stamp_a) a = f;
    if (f->header.stamp == req.stamp_b) b = f;
    held += (held.empty() ? "" : ", ") + std::to_string(f->header.stamp.toSec());
  }
  if (!a || !b) {
    res.success = false;
    res.message = std::string("stamp ") + (a ? "b " + std::to_string(req.stamp_b.toSec()) :
                                               "a " + std::to_string(req.stamp_a.toSec())) +
                  " is not held; held: [" + held + "]";
    return true;
  }
  FlowField field;
  try {
    flowBetween(*a, *b, field);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    return true;
  }
  const FlowMessages m = toFlowMsgs(field, a->header);
  res.flow = *m.flow;
  res.visible = *m.visible;
  res.pose_valid = a->optical_from_world && b->optical_from_world;
  if (res.pose_valid) res.b_in_a = toTransformMsg(*a->optical_from_world * b->optical_from_world->inverse());
  res.success = true;
  return true;
}

}  // namespace viper
