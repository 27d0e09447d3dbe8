#include "viper/ros/dataset/viper_bag_conversion.h"

#include "viper/ros/bridge/bag_writer.h"
#include "viper/ros/pacing/replay_timing.h"

#include <tf2_msgs/TFMessage.h>

#include <boost/make_shared.hpp>

#include <algorithm>
#include <deque>
#include <future>
#include <stdexcept>

namespace viper {
namespace {

using dataset::ViperModality;

struct Sequence {
  dataset::ViperSequenceFiles files;
  std::map<uint64_t, dataset::ViperCameraRow> camera;
  std::vector<uint64_t> frames;
};

// The bag's writer, with the connection headers rosbag::Bag::write stored here before (type, md5sum
// and message_definition; a latched topic's with latching and callerid too), counting what it
// writes (the counts go into ViperToBagStats).
class CountingBagWriter {
 public:
  CountingBagWriter(BagWriter& bag, ViperToBagStats& stats) : bag_(bag), stats_(stats) {}
  template <typename M>
  void write(const std::string& topic, const ros::Time& t, const boost::shared_ptr<M>& m) {
    if (!m) return;
    put(topic, t, *m, BagWriter::typeFields(*m));
  }
  template <typename M>
  void writeLatched(const std::string& topic, const ros::Time& t, const M& m) {
    std::map<std::string, std::string> header = BagWriter::typeFields(m);
    header["latching"] = "1";
    header["callerid"] = "/viper_to_bag";
    put(topic, t, m, header);
  }

 private:
  template <typename M>
  void put(const std::string& topic, const ros::Time& t, const M& m, const std::map<std::string, std::string>& header) {
    const uint64_t bytes = bag_.bytes();
    bag_.writeWithHeader(topic, t, m, header);
    ++stats_.messages;
    stats_.message_bytes += bag_.bytes() - bytes;
  }
  BagWriter& bag_;
  ViperToBagStats& stats_;
};

}  // namespace

std::string defaultViperSplit(const std::string& root) {
  const std::vector<std::string> splits = dataset::listViperSplits(root);
  if (splits.size() == 1) return splits.front();
  return std::find(splits.begin(), splits.end(), "train") != splits.end() ? "train" : "";
}

ViperToBagStats convertViperToBag(const ViperToBagOptions& options, const std::string& bag_path,
                                  const ProblemCallback& problem, const ProgressCallback& progress) {
  ViperToBagStats stats;
  auto report = [&](const std::string& p) {
    ++stats.problems;
    if (problem) problem(p);
  };
  const std::string split = options.split.empty() ? defaultViperSplit(options.root) : options.split;
  const std::vector<std::string> splits = dataset::listViperSplits(options.root);
  if (split.empty() || std::find(splits.begin(), splits.end(), split) == splits.end())
    throw std::runtime_error(options.root + ": no split '" + split + "' (give one of its " +
                             std::to_string(splits.size()) + " splits)");
  const std::vector<std::string> available = dataset::listViperSequences(options.root, split);
  const std::vector<std::string>& wanted = options.sequences.empty() ? available : options.sequences;

  std::vector<Sequence> sequences;
  size_t total = 0;
  for (const std::string& seq : wanted) {
    if (std::find(available.begin(), available.end(), seq) == available.end())
      throw std::runtime_error(options.root + "/" + split + ": no sequence '" + seq + "'");
    Sequence s;
    s.files = dataset::scanViperSequence(options.root, split, seq);
    for (const std::string& p : s.files.problems) report(p);
    for (auto it = s.files.files.begin(); it != s.files.files.end();)
      it = options.modalities.count(it->first) ? std::next(it) : s.files.files.erase(it);
    if (options.camera && !s.files.camera_csv.empty()) {
      std::vector<std::string> problems;
      try {
        s.camera = dataset::readViperCameraCsv(s.files.camera_csv, problems);
      } catch (const std::exception& e) {
        problems.push_back(std::string(e.what()) + "; sequence converted without camera");
      }
      for (const std::string& p : problems) report(p);
    }
    if (!options.camera) s.files.camera_csv.clear();
    s.frames = dataset::viperSequenceFrames(s.files, s.camera);
    for (const std::string& p : dataset::describeMissingFrames(s.files, s.camera, s.frames)) report(p);
    total += s.frames.size();
    if (!s.frames.empty()) sequences.push_back(std::move(s));
  }
  if (total == 0) throw std::runtime_error(options.root + "/" + split + ": nothing to convert");

  if (options.compression != "none" && options.compression != "lz4" && options.compression != "bz2")
    throw std::invalid_argument("compression must be none, lz4 or bz2, got '" + options.compression + "'");
  // Throws std::runtime_error "BAG: cannot write bag: ..." (also while writing, and on close).
  BagWriter bag(bag_path, options.compression, "/viper_to_bag");

  ViperMessageBuilder builder(options.frames, options.classes);
  ViperTopicSelection want;
  want.semantic_color = options.semantic_color && options.classes != nullptr;
  CountingBagWriter out(bag, stats);
  ReplayTiming timing(0.0, options.start_time);
  double base_s = 0.0, last_s = 0.0;
  auto topic = [](const char* t) { return std::string("/") + t; };

  for (size_t si = 0; si < sequences.size(); ++si) {
    const Sequence& seq = sequences[si];
    ++stats.sequences;
    builder.startSequence();
    uint32_t width = 0, height = 0;
    // Reads frame i; with prefetch, the next frames are read by other threads while this one is
    // written (decoding PNG and npz is the cost; the bag is written by this thread only).
    auto read = [&seq, &options](uint64_t frame, uint32_t w, uint32_t h) {
      std::vector<std::string> problems;
      dataset::ViperFrame f = dataset::readViperFrame(seq.files, frame, seq.camera, options.modalities, problems, w, h);
      return std::make_pair(std::move(f), std::move(problems));
    };
    std::deque<std::future<std::pair<dataset::ViperFrame, std::vector<std::string>>>> ahead;
    size_t next = 0;
    for (size_t i = 0; i < seq.frames.size(); ++i) {
      while (next < seq.frames.size() && ahead.size() <= static_cast<size_t>(std::max(0, options.prefetch))) {
        // The sequence's size is known from its first frame on; frames read before that vote alone.
        ahead.push_back(std::async(options.prefetch > 0 ? std::launch::async : std::launch::deferred, read,
                                   seq.frames[next], width, height));
        ++next;
      }
      auto [frame, problems] = ahead.front().get();
      ahead.pop_front();
      for (const std::string& p : problems) report(p);
      if (width == 0 && frame.width > 0) width = frame.width, height = frame.height;

      const double frame_s = static_cast<double>(frame.frame) / options.fps;
      if (i == 0) base_s = si == 0 ? 0.0 : last_s + 1.0 / options.fps - frame_s;
      last_s = base_s + frame_s;
      const ros::Time stamp(timing.stampOf(last_s));
      ViperFrameMessages m = builder.build(frame, stamp, want);
      for (const std::string& p : m.problems) report("sequence " + seq.files.seq + ", " + p);
      if (m.map_to_body) {
        if (i == 0) {
          tf2_msgs::TFMessage tf_static;
          tf_static.transforms.push_back(builder.bodyToOptical(stamp));
          out.writeLatched("/tf_static", stamp, tf_static);
        }
        auto tf = boost::make_shared<tf2_msgs::TFMessage>();
        tf->transforms.push_back(*m.map_to_body);
        out.write("/tf", stamp, tf);
      }
      out.write(topic(viper_topics::kColor), stamp, m.color);
      out.write(topic(viper_topics::kCameraInfo), stamp, m.camera_info);
      out.write(topic(viper_topics::kSemantic), stamp, m.semantic);
      out.write(topic(viper_topics::kSemanticColor), stamp, m.semantic_color);
      out.write(topic(viper_topics::kInstanceIds), stamp, m.instance_ids);
      out.write(topic(viper_topics::kInstancesViper), stamp, m.instances_viper);
      out.write(topic(viper_topics::kFlowForward), stamp, m.flow_forward);
      out.write(topic(viper_topics::kFlowBackward), stamp, m.flow_backward);
      out.write(topic(viper_topics::kOdom), stamp, m.odom);
      out.write(topic(viper_topics::kBoxes), stamp, m.boxes);
      out.write(topic(viper_topics::kBoxesOptical), stamp, m.boxes_optical);
      ++stats.frames;
      if (progress) progress(stats.frames, total);
    }
  }
  bag.close();
  return stats;
}

}  // namespace viper
