#include "viper/ros/bridge/raw_frames.h"

#include <functional>
#include <set>
#include <sstream>

namespace viper {

CaptureRawFrames::CaptureRawFrames(const std::string& path, std::optional<double> start_time_s,
                                   const std::string& frame_id)
    : path_(path), timing_(0.0, start_time_s), frame_id_(frame_id) {
  try {
    reader_ = std::make_unique<CaptureReader>(path);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read capture '" + path + "': " + e.what());
  }
}

bool CaptureRawFrames::next(FrameMessages& out) {
  while (!ended_) {
    const uint64_t offset = reader_->offset();
    try {
      if (reader_->next(frame_) == CaptureReader::Status::kEnd) break;
    } catch (const CaptureFormatError& e) {
      std::ostringstream what;
      what << "capture '" << path_ << "' is damaged at byte " << e.offset() << " (after "
           << (last_number_ ? "frame " + std::to_string(*last_number_) : std::string("no frame")) << "; " << frames_
           << " frames read): " << e.what();
      problems_.push_back(what.str());
      break;
    }
    const std::string problem = validateFrame(frame_);
    if (!problem.empty()) {
      problems_.push_back("dropping frame " + std::to_string(frame_.number) + " of '" + path_ + "' (byte " +
                          std::to_string(offset) + "): " + problem);
      continue;
    }
    std_msgs::Header header;
    header.stamp = ros::Time(timing_.stampOf(frame_.time_s));
    header.frame_id = frame_id_;
    if (timing_.lastWasClamped())
      warnings_.push_back("frame " + std::to_string(frame_.number) + " of '" + path_ + "' goes back in time (" +
                          std::to_string(frame_.time_s) + " s); stamped 1 ms after the previous frame");
    try {
      out = frameMessages(frame_, header, meshes_, pools_);
    } catch (const std::invalid_argument& e) {
      problems_.push_back("dropping frame " + std::to_string(frame_.number) + " of '" + path_ + "' (byte " +
                          std::to_string(offset) + "): " + e.what());
      continue;
    }
    if (!out.camera_problem.empty() && !camera_warned_) {
      camera_warned_ = true;
      warnings_.push_back("frame " + std::to_string(frame_.number) + " of '" + path_ + "': " + out.camera_problem);
    }
    last_number_ = frame_.number;
    ++frames_;
    return true;
  }
  ended_ = true;
  return false;
}

BagRawFrames::BagRawFrames(const std::string& path, const std::string& ns) : path_(path), ns_(ns) {
  const std::set<std::string> topics = {ns + "/draws", ns + "/draw_ids", ns + "/depth/image_raw",
                                        ns + "/primitive_ids", ns + "/color/image_raw", ns + "/color/camera_info",
                                        ns + "/mesh_store"};
  try {
    bag_ = std::make_unique<BagReader>(path, topics);
  } catch (const BagReadError& e) {
    throw std::runtime_error("cannot open bag '" + path + "': " + e.problem());
  }
  for (const dataset::BagConnection* c : bag_->connections())
    if (c->topic == ns + "/draws") frame_count_ += c->messages;
  if (frame_count_ == 0) throw std::runtime_error("bag '" + path + "' has no " + ns + "/draws: not a raw bag");
}

bool BagRawFrames::complete(const FrameMessages& m) const {
  return m.draws && m.draw_ids && m.depth && m.primitive_ids && m.color && m.camera_info;
}

bool BagRawFrames::takeOldest(FrameMessages& out) {
  const auto oldest = pending_.begin();
  const bool ok = complete(oldest->second);
  if (ok) out = oldest->second;
  else
    problems_.push_back("bag '" + path_ + "': the raw messages of stamp " + std::to_string(oldest->first.toSec()) +
                        " are incomplete (draws, draw_ids, depth, primitive_ids, color and camera_info needed); "
                        "frame dropped");
  pending_.erase(oldest);
  return ok;
}

bool BagRawFrames::next(FrameMessages& out) {
  try {
    while (bag_ && bag_->next(m_)) {
      const BagReadMessage& m = m_;
      const std::string topic = m.topic().substr(ns_.size());
      // The message, typed, and where it goes in its stamp's frame.
      std::function<void(FrameMessages&)> put;
      std::optional<ros::Time> stamp;
      auto typed = [&](auto msg, auto member) {
        if (!msg) return;
        stamp = msg->header.stamp;
        put = [msg, member](FrameMessages& f) { f.*member = msg; };
      };
      if (topic == "/draws") typed(m.instantiate<DrawList>(), &FrameMessages::draws);
      else if (topic == "/mesh_store") typed(m.instantiate<MeshStore>(), &FrameMessages::mesh_store);
      else if (topic == "/color/camera_info") typed(m.instantiate<sensor_msgs::CameraInfo>(), &FrameMessages::camera_info);
      else if (topic == "/draw_ids") typed(m.instantiate<sensor_msgs::Image>(), &FrameMessages::draw_ids);
      else if (topic == "/depth/image_raw") typed(m.instantiate<sensor_msgs::Image>(), &FrameMessages::depth);
      else if (topic == "/primitive_ids") typed(m.instantiate<sensor_msgs::Image>(), &FrameMessages::primitive_ids);
      else typed(m.instantiate<sensor_msgs::Image>(), &FrameMessages::color);
      if (!stamp) {
        problems_.push_back("bag '" + path_ + "': " + m.topic() + " carries " + m.datatype() + "; message skipped");
        continue;
      }
      put(pending_[*stamp]);
      // A recorded bag interleaves the messages of neighbouring frames, and a frame's mesh store may
      // come after its images: the oldest frame goes once two later frames are whole (or, if it is
      // not whole itself, once eight are).
      size_t later_whole = 0;
      for (auto p = std::next(pending_.begin()); p != pending_.end(); ++p) later_whole += complete(p->second);
      const bool whole = complete(pending_.begin()->second);
      if ((whole && later_whole >= 2) || later_whole >= 8) {
        if (takeOldest(out)) return true;
      }
    }
  } catch (const BagReadError& e) {
    problems_.push_back("bag '" + path_ + "' cannot be read further: " + e.problem());
  } catch (const std::exception& e) {  // a message that does not deserialise
    problems_.push_back("bag '" + path_ + "' cannot be read further: " + e.what());
  }
  bag_.reset();
  while (!pending_.empty()) {
    if (takeOldest(out)) return true;
  }
  return false;
}

void writeRawFrame(BagWriter& bag, const std::string& ns, const FrameMessages& m) {
  const std::string prefix = ns == "/" ? "" : ns;
  if (m.mesh_store) bag.write(prefix + "/mesh_store", m.mesh_store, /*latched=*/true);
  bag.write(prefix + "/color/image_raw", m.color);
  bag.write(prefix + "/color/camera_info", m.camera_info);
  bag.write(prefix + "/depth/image_raw", m.depth);
  bag.write(prefix + "/depth/camera_info", m.camera_info);
  bag.write(prefix + "/draw_ids", m.draw_ids);
  bag.write(prefix + "/primitive_ids", m.primitive_ids);
  bag.write(prefix + "/draws", m.draws);
}

std::unique_ptr<RawFrames> openRawFrames(const std::string& path) {
  const bool capture = path.size() >= 5 && path.compare(path.size() - 5, 5, ".vcap") == 0;
  if (capture) return std::make_unique<CaptureRawFrames>(path);
  return std::make_unique<BagRawFrames>(path);
}

}  // namespace viper
