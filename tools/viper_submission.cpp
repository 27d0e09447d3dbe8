// viper_submission: a user's predictions, recorded in a bag on the topics the evaluate node reads
// (semantic, instances, flow, odom), written as VIPER's submission files (the devkit's
// EVALUATION.md; include/viper/dataset/viper_submission.h). Each prediction's header stamp is
// mapped to its frame number through the ground-truth bag of the sequence (generate's
// ROOT/SPLIT/bag/SEQ.bag: /capture/draws carries stamp and frame_number). A bad message is
// reported (topic, stamp, what is wrong) and skipped. Exit code: 0 = every message written, 1 =
// some skipped, the rest written, 2 = usage, bag or write error. docs/evaluate.md has the details.
#include "command_line.h"
#include "viper/dataset/viper_submission.h"
#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/evaluation/evaluate_inputs.h"

#include <sensor_msgs/CameraInfo.h>
#include <viper/DrawList.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>

namespace {

namespace ds = viper::dataset;
namespace fs = std::filesystem;

struct Options {
  std::string bag, frames, out;
  int seq = -1;
  std::string semantic = "/perception/semantic", instances = "/perception/instances", flow = "/perception/flow",
              odom = "/perception/odom";
  std::string draws = "/capture/draws", camera_info = "/capture/color/camera_info";
  bool flow_stamp_second = false, estimate_optical = false;
};

// The command line's options, into `o` (what only the whole line tells: check()).
void addOptions(CLI::App& app, Options& o, std::string& seq, std::string& flow_stamp, std::string& estimate) {
  app.add_option("--bag", o.bag, "the predictions, recorded on the topics below")
      ->required()
      ->type_name("PREDICTIONS.bag");
  app.add_option("--frames", o.frames,
                 "the sequence's ground-truth bag (generate's ROOT/SPLIT/bag/SEQ.bag): FRAME is the frame number of "
                 "the prediction's stamp in its draw lists")
      ->required()
      ->type_name("GT.bag");
  app.add_option("--out", o.out, "the submission's folder")->required()->type_name("DIR");
  app.add_option("--seq", seq, "the sequence id, 0..999 (default: GT.bag's name, 001.bag: 1)")->type_name("N");
  app.add_option("--semantic", o.semantic, "semantic classes (sensor_msgs/Image, mono8)")
      ->type_name("TOPIC")
      ->capture_default_str();
  app.add_option("--instances", o.instances, "instances (viper/InstancePredictionArray)")
      ->type_name("TOPIC")
      ->capture_default_str();
  app.add_option("--flow", o.flow, "flow (sensor_msgs/Image, 32FC2)")->type_name("TOPIC")->capture_default_str();
  app.add_option("--odom", o.odom, "odometry (nav_msgs/Odometry)")->type_name("TOPIC")->capture_default_str();
  app.add_option("--flow-stamp", flow_stamp, "flow stamped with the first image of its pair, or the second")
      ->type_name("first|second")
      ->capture_default_str();
  app.add_option("--odometry-estimate-frame", estimate, "the frame the odometry estimates: the body or the camera's")
      ->type_name("body|optical")
      ->capture_default_str();
  app.add_option("--draws", o.draws, "GT.bag's draw lists (stamps and frame numbers)")
      ->type_name("TOPIC")
      ->capture_default_str();
  app.add_option("--camera-info", o.camera_info, "GT.bag's camera info (the frame size)")
      ->type_name("TOPIC")
      ->capture_default_str();
}

// What only the whole command line tells; returns the error, empty if none.
std::string check(Options& o, const std::string& seq, const std::string& flow_stamp, const std::string& estimate) {
  const auto number = [](const std::string& t) {
    return !t.empty() && t.size() <= 3 && t.find_first_not_of("0123456789") == std::string::npos ? std::stoi(t) : -1;
  };
  o.seq = number(seq.empty() ? fs::path(o.frames).stem().string() : seq);
  o.flow_stamp_second = flow_stamp == "second";
  o.estimate_optical = estimate == "optical";
  if (o.seq < 0 && seq.empty()) return "--seq is required: the name of " + o.frames + " is not a number 0..999";
  if (o.seq < 0) return "--seq must be a number 0..999 (VIPER's sequence ids)";
  if (flow_stamp != "first" && flow_stamp != "second") return "--flow-stamp must be first or second";
  if (estimate != "body" && estimate != "optical") return "--odometry-estimate-frame must be body or optical";
  return "";
}

// The ground-truth sequence: frame number per stamp, and the frame size.
struct Frames {
  std::map<ros::Time, uint64_t> by_stamp;
  std::set<uint64_t> numbers;
  uint32_t width = 0, height = 0;
};

// The bag at `path` for `topics` (null: an error, said).
std::unique_ptr<viper::BagReader> openBag(const std::string& path, const std::set<std::string>& topics,
                                          const char* what) {
  try {
    return std::make_unique<viper::BagReader>(path, topics);
  } catch (const viper::BagReadError& e) {
    std::cerr << "viper_submission: cannot open " << what << " " << path << ": " << e.problem() << "\n";
    return nullptr;
  }
}

bool readFrames(const Options& o, Frames& f) {
  std::unique_ptr<viper::BagReader> bag = openBag(o.frames, {o.draws}, "the ground-truth bag");
  if (!bag) return false;
  viper::BagReadMessage m;
  while (bag->next(m))
    if (const auto d = m.instantiate<viper::DrawList>()) {
      f.by_stamp.emplace(d->header.stamp, d->frame_number);
      f.numbers.insert(d->frame_number);
    }
  for (viper::BagReader info(o.frames, {o.camera_info}); info.next(m);)
    if (const auto c = m.instantiate<sensor_msgs::CameraInfo>()) {
      f.width = c->width, f.height = c->height;
      break;
    }
  if (f.by_stamp.empty() || f.width == 0 || f.height == 0) {
    std::cerr << "viper_submission: " << o.frames << " has no "
              << (f.by_stamp.empty() ? "viper/DrawList on " + o.draws : "sensor_msgs/CameraInfo on " + o.camera_info)
              << " (give the ground-truth bag generate wrote: ROOT/SPLIT/bag/SEQ.bag)\n";
    return false;
  }
  return true;
}

class Writer {
 public:
  Writer(const Options& o, const Frames& f) : o_(o), frames_(f) {}

  // Writes one message of the predictions' bag; "" or what is wrong with it.
  std::string write(const viper::BagReadMessage& m, ros::Time& stamp) {
    const std::string& topic = m.topic();
    if (topic == o_.semantic) {
      const auto msg = m.instantiate<sensor_msgs::Image>();
      if (!msg) return "not a sensor_msgs/Image (mono8)";
      stamp = msg->header.stamp;
      ds::Image8 ids;
      std::string problem = viper::imageFromMsg(*msg, "mono8", ids);
      if (problem.empty()) problem = checkSize(ids.width, ids.height);
      if (problem.empty()) problem = frameOf(stamp, false);
      if (problem.empty()) ds::writeSubmissionSemantic(dir(ds::kSubmissionClsDir), o_.seq, frame_, ids);
      return problem;
    }
    if (topic == o_.instances) {
      const auto msg = m.instantiate<viper::InstancePredictionArray>();
      if (!msg) return "not a viper/InstancePredictionArray";
      stamp = msg->header.stamp;
      std::vector<viper::BoxedInstance> boxed;
      std::string problem = viper::toBoxedInstances(*msg, frames_.width, frames_.height, boxed);
      if (problem.empty()) problem = frameOf(stamp, false);
      if (!problem.empty()) return problem;
      std::vector<ds::SubmissionInstance> instances;
      for (const viper::BoxedInstance& b : boxed) {
        ds::SubmissionInstance& p = instances.emplace_back();
        p.class_id = b.class_id, p.confidence = b.score;
        p.mask = ds::Image8{frames_.width, frames_.height, 1, std::vector<uint8_t>(size_t(frames_.width) * frames_.height)};
        for (uint32_t y = 0; y < b.height; ++y)
          std::copy_n(b.mask + size_t(y) * b.width, b.width, &p.mask.data[size_t(b.y0 + y) * frames_.width + b.x0]);
      }
      try {
        if (!inst_cleared_) clearInstanceMasks();
        rows_[frame_] = ds::writeSubmissionInstances(dir(ds::kSubmissionInstDir), o_.seq, frame_, instances);
      } catch (const std::invalid_argument& e) {
        return e.what();
      }
      return "";
    }
    if (topic == o_.flow) {
      const auto msg = m.instantiate<sensor_msgs::Image>();
      if (!msg) return "not a sensor_msgs/Image (32FC2)";
      stamp = msg->header.stamp;
      ds::FlowImage flow;
      std::string problem = viper::flowFromMsg(*msg, flow);
      if (problem.empty()) problem = checkSize(flow.width, flow.height);
      if (problem.empty()) problem = frameOf(stamp, o_.flow_stamp_second);
      if (problem.empty() && frames_.numbers.count(frame_ + 1) == 0)
        problem = "frame " + std::to_string(frame_) + " is the last of " + o_.frames + ": no pair to flow to";
      if (problem.empty()) ds::writeSubmissionFlow(dir(ds::kSubmissionFlowDir), o_.seq, frame_, flow);
      return problem;
    }
    const auto msg = m.instantiate<nav_msgs::Odometry>();
    if (!msg) return "not a nav_msgs/Odometry";
    stamp = msg->header.stamp;
    Eigen::Isometry3d pose;
    std::string problem = viper::poseFromOdometry(*msg, pose);
    if (problem.empty()) problem = frameOf(stamp, false);
    if (problem.empty()) poses_[frame_] = {stamp.toSec(), pose};
    return problem;
  }

  // Writes what needs every message first: instances.csv and the odometry file.
  void finish() {
    if (inst_cleared_) {
      std::vector<ds::SubmissionInstanceRow> rows;
      for (const auto& [frame, r] : rows_) rows.insert(rows.end(), r.begin(), r.end());
      ds::writeInstancesCsv(dir(ds::kSubmissionInstDir), o_.seq, rows);
    }
    if (poses_.empty()) return;
    std::vector<double> stamps;
    std::vector<Eigen::Isometry3d> estimates;
    for (const auto& [frame, p] : poses_) stamps.push_back(p.first), estimates.push_back(p.second);
    ds::writeSubmissionOdometry(dir(ds::kSubmissionOdometryDir), o_.seq,
                                ds::kittiSubmissionPoses(stamps, estimates, o_.estimate_optical));
  }

 private:
  std::string dir(const char* task) const {
    const fs::path d = fs::path(o_.out) / task;
    fs::create_directories(d);
    return d.string();
  }
  std::string checkSize(uint32_t w, uint32_t h) const {
    if (w == frames_.width && h == frames_.height) return "";
    return "size " + std::to_string(w) + "x" + std::to_string(h) + ", the frames of " + o_.frames + " are " +
           std::to_string(frames_.width) + "x" + std::to_string(frames_.height);
  }
  // Sets frame_ to the frame of `stamp` (with `before`, the frame before it: flow stamped with the
  // second image of its pair).
  std::string frameOf(const ros::Time& stamp, bool before) {
    const auto it = frames_.by_stamp.find(stamp);
    if (it == frames_.by_stamp.end())
      return "its stamp is not among the " + std::to_string(frames_.by_stamp.size()) + " frames of " + o_.frames;
    if (before && (it->second == 0 || frames_.numbers.count(it->second - 1) == 0))
      return "frame " + std::to_string(it->second) + " has no frame before it in " + o_.frames + " (--flow-stamp second)";
    frame_ = before ? it->second - 1 : it->second;
    return "";
  }
  // Masks of this sequence left by an earlier run would be zipped with the new ones.
  void clearInstanceMasks() {
    const std::string prefix = ds::submissionFrameName(o_.seq, 0).substr(0, 4);
    for (const auto& e : fs::directory_iterator(dir(ds::kSubmissionInstDir))) {
      const std::string name = e.path().filename().string();
      if (name.rfind(prefix, 0) == 0 && e.path().extension() == ".png") fs::remove(e.path());
    }
    inst_cleared_ = true;
  }

  const Options& o_;
  const Frames& frames_;
  uint64_t frame_ = 0;
  bool inst_cleared_ = false;
  std::map<uint64_t, std::vector<ds::SubmissionInstanceRow>> rows_;
  std::map<uint64_t, std::pair<double, Eigen::Isometry3d>> poses_;
};

int run(const Options& o) {
  Frames frames;
  if (!readFrames(o, frames)) return 2;
  std::unique_ptr<viper::BagReader> bag =
      openBag(o.bag, {o.semantic, o.instances, o.flow, o.odom}, "the predictions' bag");
  if (!bag) return 2;
  viper::BagReader& view = *bag;
  if (view.size() == 0) {
    std::cerr << "viper_submission: " << o.bag << " has no messages on " << o.semantic << ", " << o.instances << ", "
              << o.flow << " or " << o.odom << "\n";
    return 2;
  }
  Writer writer(o, frames);
  std::map<std::string, size_t> written, skipped;
  viper::BagReadMessage m;
  // A damaged chunk's messages cannot be read: each is skipped, as a bad message.
  const auto damaged = [&](const viper::BagReadError& e) {
    for (const viper::BagSkippedMessage& s : e.skipped()) {
      ++skipped[s.topic()];
      std::cerr << "viper_submission: skipping " << s.topic() << " at stamp " << s.time << ": cannot be read: "
                << e.problem() << "\n";
    }
  };
  while (view.nextReadingOn(m, damaged)) {
    ros::Time stamp = m.time();
    std::string problem;
    try {
      problem = writer.write(m, stamp);
    } catch (const ros::Exception& e) {  // a message that does not deserialize
      problem = std::string("cannot be read: ") + e.what();
    } catch (const std::exception& e) {
      std::cerr << "viper_submission: " << m.topic() << " at stamp " << stamp << ": " << e.what() << "\n";
      return 2;
    }
    if (problem.empty()) {
      ++written[m.topic()];
      continue;
    }
    ++skipped[m.topic()];
    std::cerr << "viper_submission: skipping " << m.topic() << " at stamp " << stamp << ": " << problem
              << "\n";
  }
  try {
    writer.finish();
  } catch (const std::exception& e) {
    std::cerr << "viper_submission: " << e.what() << "\n";
    return 2;
  }
  size_t bad = 0;
  for (const std::string& t : {o.semantic, o.instances, o.flow, o.odom}) {
    std::cout << "viper_submission: " << t << ": " << written[t] << " written, " << skipped[t] << " skipped\n";
    bad += skipped[t];
  }
  std::cout << "viper_submission: sequence " << ds::submissionFrameName(o.seq, 0).substr(0, 3) << " in " << o.out
            << "\n";
  return bad == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Writes the predictions of PREDICTIONS.bag as VIPER's submission files: DIR/cls/SEQ_FRAME.png,\n"
      "DIR/inst/SEQ_FRAME_CLASS_INSTANCE.png + DIR/inst/instances.csv, DIR/flow/SEQ_FRAME.flo,\n"
      "DIR/odometry/SEQ.txt (KITTI axes). A topic without messages is left out.",
      "viper_submission");
  Options o;
  std::string seq, flow_stamp = "first", estimate = "body";
  addOptions(app, o, seq, flow_stamp, estimate);
  app.footer("Exit status: 0 all written; 1 bad messages skipped; 2 error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  if (const std::string error = check(o, seq, flow_stamp, estimate); !error.empty())
    return viper_tools::usageError(app, error);
  try {
    return run(o);
  } catch (const std::exception& e) {  // a damaged bag (BagReadError names it)
    std::cerr << "viper_submission: " << e.what() << "\n";
  }
  return 2;
}
