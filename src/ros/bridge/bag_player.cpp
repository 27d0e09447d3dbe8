#include "viper/ros/bridge/bag_player.h"

#include "viper/dataset/bag_file_reader.h"

#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <topic_tools/shape_shifter.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace viper {

namespace {

const char* const kImage = "sensor_msgs/Image";
const char* const kCameraInfo = "sensor_msgs/CameraInfo";
const char* const kDrawList = "viper/DrawList";
const char* const kMeshStore = "viper/MeshStore";
const char* const kTf = "tf2_msgs/TFMessage";
const char* const kTfStatic = "/tf_static";

// /tf_static is latched whatever the bag says: tf2 listeners that start later get it only so.
bool latched(const dataset::BagConnection& c) { return c.field("latching") == "1" || c.topic == kTfStatic; }

// Whether `bag` is a file; a ROS_FATAL that says how to give it where it is not (at start, and
// before each pass: a bag removed meanwhile).
bool bagFileIsThere(const std::string& bag) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(bag, ec)) return true;
  ROS_FATAL("bag_player: no such file '%s' (a relative path is taken from the node's working directory, '%s': "
            "roslaunch starts nodes in $ROS_HOME; give an absolute path)",
            bag.c_str(), std::filesystem::current_path(ec).c_str());
  return false;
}

}  // namespace

std::string readBagPlayerOptions(const ros::NodeHandle& pnh, BagPlayerOptions& o) {
  pnh.param<std::string>("bag", o.bag, "");
  pnh.param("rate", o.rate, 1.0);
  pnh.param("start_delay_s", o.start_delay_s, 0.0);
  pnh.param("publish_clock", o.publish_clock, true);
  pnh.param("queue_size", o.queue_size, 100);
  pnh.param("exit_when_done", o.exit_when_done, false);
  pnh.param("loop", o.loop, false);
  if (o.bag.empty()) return "~bag is empty: give the raw bag to play";
  if (!(o.rate >= 0.0)) return "~rate must be >= 0 (0: as fast as possible), got " + std::to_string(o.rate);
  if (!(o.start_delay_s >= 0.0)) return "~start_delay_s must be >= 0, got " + std::to_string(o.start_delay_s);
  if (o.queue_size < 1) return "~queue_size must be >= 1, got " + std::to_string(o.queue_size);
  return readPaceOptions(pnh, o.pace);
}

BagPlayer::BagPlayer(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh), pnh_(pnh) {}

BagPlayer::~BagPlayer() { stop(); }

bool BagPlayer::start(bool is_node) {
  is_node_ = is_node;
  const std::string problem = readBagPlayerOptions(pnh_, options_);
  if (!problem.empty()) {
    ROS_FATAL("bag_player %s: %s", pnh_.getNamespace().c_str(), problem.c_str());
    return false;
  }
  if (!bagFileIsThere(options_.bag)) return false;
  std::vector<dataset::BagConnection> connections;
  try {
    connections = dataset::BagFileReader(options_.bag).connections();
  } catch (const std::exception& e) {
    ROS_FATAL("bag_player: cannot read '%s': %s (a truncated bag has no index: 'rosbag reindex' recovers "
              "the messages before the damage)",
              options_.bag.c_str(), e.what());
    return false;
  }
  for (const dataset::BagConnection& c : connections) {
    if (c.messages == 0 || pubs_.count(c.topic)) continue;  // rosbag::View lists connections with messages
    const uint32_t q = static_cast<uint32_t>(options_.queue_size);
    const bool latch = latched(c);
    const std::string& type = c.field("type");
    if (type == kImage) pubs_[c.topic] = nh_.advertise<sensor_msgs::Image>(c.topic, q, latch);
    else if (type == kCameraInfo) pubs_[c.topic] = nh_.advertise<sensor_msgs::CameraInfo>(c.topic, q, latch);
    else if (type == kDrawList) pubs_[c.topic] = nh_.advertise<DrawList>(c.topic, q, latch);
    else if (type == kMeshStore) pubs_[c.topic] = nh_.advertise<MeshStore>(c.topic, q, latch);
    else if (type == kTf) pubs_[c.topic] = nh_.advertise<tf2_msgs::TFMessage>(c.topic, q, latch);
    else {
      topic_tools::ShapeShifter shape;
      shape.morph(c.field("md5sum"), type, c.field("message_definition"), latch ? "1" : "0");
      pubs_[c.topic] = shape.advertise(nh_, c.topic, q, latch);
    }
  }
  if (pubs_.empty()) {
    ROS_FATAL("bag_player: '%s' holds no message", options_.bag.c_str());
    return false;
  }
  if (options_.publish_clock) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  gate_ = std::make_unique<PaceGate>(nh_, options_.pace, "bag_player");
  ROS_INFO("bag_player: playing '%s' (%zu topics) at rate %g%s%s", options_.bag.c_str(), pubs_.size(), options_.rate,
           options_.loop ? ", looping" : "",
           gate_->active() ? (", at most " + std::to_string(options_.pace.max_in_flight) + " frames ahead of '" +
                              options_.pace.topic + "'").c_str() : "");
  thread_ = std::thread(&BagPlayer::run, this);
  return true;
}

void BagPlayer::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

bool BagPlayer::sleepUntil(const ros::WallTime& t) {
  while (!stop_ && ros::ok()) {
    const double left = (t - ros::WallTime::now()).toSec();
    if (left <= 0.0) return true;
    ros::WallDuration(std::min(left, 0.1)).sleep();
  }
  return false;
}

namespace {

template <typename T>
void deserialise(ros::serialization::IStream& in, T& msg) {
  ros::serialization::deserialize(in, msg);
}

// Publishes msg with its header stamp `shift` later; returns the bag's stamp.
template <typename T>
ros::Time publishShifted(ros::Publisher& pub, const ros::Duration& shift, const boost::shared_ptr<T>& msg) {
  const ros::Time stamp = msg->header.stamp;
  if (!shift.isZero() && !stamp.isZero()) msg->header.stamp += shift;
  pub.publish(msg);
  return stamp;
}

// A type of another definition does not deserialise as T (rosbag's instantiate<T> refuses it too).
template <typename T>
void checkType(const dataset::BagMessage& m) {
  if (m.connection->field("md5sum") != ros::message_traits::md5sum<T>())
    throw std::runtime_error("a " + m.connection->field("type") + " message on " + m.connection->topic +
                             " does not deserialise (md5sum " + m.connection->field("md5sum") + ", not " +
                             ros::message_traits::md5sum<T>() + ")");
}

template <typename T>
ros::Time publishShifted(ros::Publisher& pub, const dataset::BagMessage& m, const ros::Duration& shift) {
  checkType<T>(m);
  const boost::shared_ptr<T> msg = boost::make_shared<T>();
  ros::serialization::IStream in(const_cast<uint8_t*>(m.data), m.size);
  ros::serialization::deserialize(in, *msg);
  return publishShifted(pub, shift, msg);
}

}  // namespace

namespace {

// An image's fields before its pixels, from the start of its serialised bytes; returns the number
// of pixel bytes (the byte vector's length). Throws StreamOverrunException where `in` ends first.
uint32_t imageFields(ros::serialization::IStream& in, sensor_msgs::Image& image) {
  in.next(image.header);
  in.next(image.height);
  in.next(image.width);
  in.next(image.encoding);
  in.next(image.is_bigendian);
  in.next(image.step);
  uint32_t size = 0;
  in.next(size);
  return size;
}

}  // namespace

uint8_t* BagPlayer::ImageSink::bulk(const dataset::BagConnection& connection, const uint8_t* prefix,
                                    uint32_t available, uint32_t size, uint32_t& offset) {
  if (connection.field("type") != kImage || connection.field("md5sum") != ros::message_traits::md5sum<sensor_msgs::Image>())
    return nullptr;
  sensor_msgs::Image fields;
  uint32_t pixels = 0;
  try {
    ros::serialization::IStream in(const_cast<uint8_t*>(prefix), available);
    pixels = imageFields(in, fields);
    offset = static_cast<uint32_t>(in.getData() - prefix);
  } catch (const ros::serialization::StreamOverrunException&) {
    return nullptr;  // not all of its fields are in yet
  }
  if (pixels != size - offset) return nullptr;  // not a whole image: left to publishImage to name
  sensor_msgs::ImagePtr msg = pools[connection.topic].takeBytes(pixels);
  if (msg->data.size() != pixels) msg->data.resize(pixels);  // a new message
  // By its pixels: the reader may read the next chunk ahead (another message of the same topic).
  return (pending[msg->data.data()] = msg)->data.data();
}

// An image as ROS deserialises it, into a message of the topic's pool (its pages in use already:
// a new 1080p message's would be faulted in and zeroed): its pixels decompressed straight into
// the message where the reader could (the sink's pending message), else copied once (ROS's
// deserialiser of a byte vector resizes it, zeroing the bytes, before it copies them).
ros::Time BagPlayer::publishImage(ros::Publisher& pub, const dataset::BagMessage& m, const ros::Duration& shift) {
  checkType<sensor_msgs::Image>(m);
  sensor_msgs::ImagePtr msg;
  const uint8_t* bytes = nullptr;
  sensor_msgs::Image fields;
  uint32_t size = 0;
  if (m.bulk) {
    auto pending = image_sink_.pending.find(m.bulk);
    if (pending == image_sink_.pending.end())
      throw std::logic_error("bag_player: the pixels of an image on " + m.connection->topic + " are not its message's");
    msg = std::move(pending->second);
    image_sink_.pending.erase(pending);
    ros::serialization::IStream in(const_cast<uint8_t*>(m.data), m.bulk_offset);
    size = imageFields(in, fields);
  } else {
    ros::serialization::IStream in(const_cast<uint8_t*>(m.data), m.size);
    size = imageFields(in, fields);
    bytes = in.advance(size);  // throws StreamOverrunException past the message's end
    msg = image_sink_.pools[m.connection->topic].takeBytes(size);
  }
  msg->header = std::move(fields.header);
  msg->height = fields.height;
  msg->width = fields.width;
  msg->encoding = std::move(fields.encoding);
  msg->is_bigendian = fields.is_bigendian;
  msg->step = fields.step;
  if (bytes) msg->data.assign(bytes, bytes + size);
  return publishShifted(pub, shift, msg);
}

ros::Time BagPlayer::publishTf(ros::Publisher& pub, const dataset::BagMessage& m, const ros::Duration& shift) {
  checkType<tf2_msgs::TFMessage>(m);
  auto msg = boost::make_shared<tf2_msgs::TFMessage>();
  ros::serialization::IStream in(const_cast<uint8_t*>(m.data), m.size);
  ros::serialization::deserialize(in, *msg);
  ros::Time latest;
  for (geometry_msgs::TransformStamped& t : msg->transforms) {
    latest = std::max(latest, t.header.stamp);
    if (!shift.isZero() && !t.header.stamp.isZero()) t.header.stamp += shift;
  }
  if (m.connection->topic != kTfStatic) {
    pub.publish(msg);
    return latest;
  }
  // A latched publisher keeps only its last message, so /tf_static goes out as the union of the
  // static transforms so far (by child frame, the latest of each), as tf2_ros's static broadcaster
  // sends it. Every pass sends them again: a bag may change one on the way (generate does when
  // the camera's mounting changes), and the start of the next pass has the first value again.
  for (const geometry_msgs::TransformStamped& t : msg->transforms) tf_static_[t.child_frame_id] = t;
  auto all = boost::make_shared<tf2_msgs::TFMessage>();
  for (const auto& [child, t] : tf_static_) all->transforms.push_back(t);
  pub.publish(all);
  return latest;
}

ros::Time BagPlayer::publish(const dataset::BagMessage& m, const ros::Duration& shift) {
  ros::Publisher& pub = pubs_[m.connection->topic];
  const std::string& type = m.connection->field("type");
  if (type == kImage) return publishImage(pub, m, shift);
  if (type == kCameraInfo) return publishShifted<sensor_msgs::CameraInfo>(pub, m, shift);
  if (type == kDrawList) return publishShifted<DrawList>(pub, m, shift);
  if (type == kMeshStore) return publishShifted<MeshStore>(pub, m, shift);
  if (type == kTf) return publishTf(pub, m, shift);
  // Other types as they are: the bytes with the connection's type (as rosbag's ShapeShifter gets them).
  const auto shape = boost::make_shared<topic_tools::ShapeShifter>();
  shape->morph(m.connection->field("md5sum"), type, m.connection->field("message_definition"),
               m.connection->field("latching"));
  ros::serialization::IStream in(const_cast<uint8_t*>(m.data), m.size);
  shape->read(in);
  pub.publish(shape);
  return ros::Time();
}

void BagPlayer::Span::add(const ros::Time& t) {
  if (t.isZero()) return;
  if (values == 0) {
    first = last = t;
    values = 1;
  } else if (t > last) {  // counts rises: the messages of one frame share their time
    last = t;
    ++values;
  } else if (t < first) {
    first = t;
  }
}

double BagPlayer::Span::step() const {
  const double span = (last - first).toSec();
  return span + (values > 1 && span > 0.0 ? span / static_cast<double>(values - 1) : 0.1);
}

bool BagPlayer::playPass(const ros::Duration& shift, Progress& p, PassSpan& span) {
  if (!bagFileIsThere(options_.bag)) return false;
  try {
    dataset::BagFileReader bag(options_.bag);
    bag.setBulkSink(&image_sink_);
    int64_t cpu_mark = CpuMeter::threadCpuNs();  // this thread's CPU, reading included, by frame
    dataset::BagMessage m;
    while (bag.next(m)) {
      if (stop_ || !ros::ok()) return false;
      const ros::Time time(m.sec, m.nsec);
      const ros::Time t = time + shift;
      if (p.count == 0 || t > p.last) {
        const int64_t now = CpuMeter::threadCpuNs();
        cpu_.add(now - cpu_mark, p.count > 0);
        cpu_mark = now;
      }
      // A new frame (its messages share their time) waits for room in the pipeline.
      if ((p.count == 0 || t > p.last) && !gate_->waitForRoom(stop_)) return false;
      if (p.count == 0) {
        p.first = t;
        p.wall_start = ros::WallTime::now();
      } else if (options_.rate > 0.0 &&
                 !sleepUntil(p.wall_start + ros::WallDuration((t - p.first).toSec() / options_.rate))) {
        return false;
      }
      // The clock first, so sim-time subscribers see the message's time when it arrives.
      if (options_.publish_clock && t > p.last) {
        rosgraph_msgs::Clock clock;
        clock.clock = t;
        clock_pub_.publish(clock);
      }
      p.last = t;
      span.times.add(time);
      const ros::Time stamp = publish(m, shift);
      span.stamps.add(stamp);
      // Transforms come at a rate of their own: frames are what the other messages stamp.
      if (!stamp.isZero() && m.connection->field("type") != kTf) gate_->sent(stamp + shift);
      published_ = ++p.count;
    }
    return true;
  } catch (const std::exception& e) {
    ROS_ERROR("bag_player: '%s' is damaged after %lu messages (bag time %.6f): %s; stopping, the messages before "
              "were published",
              options_.bag.c_str(), static_cast<unsigned long>(p.count), (p.last - shift).toSec(), e.what());
    return false;
  }
}

void BagPlayer::run() {
  if (options_.start_delay_s > 0.0 && !sleepUntil(ros::WallTime::now() + ros::WallDuration(options_.start_delay_s)))
    return;
  Progress progress;
  ros::Duration shift(0);
  for (uint64_t pass = 1;; ++pass) {
    PassSpan span;
    if (!playPass(shift, progress, span) || !options_.loop || stop_ || !ros::ok()) break;
    shift += span.step();
    ROS_INFO("bag_player: '%s' from the start again (pass %lu), times, header and tf stamps %.3f s later",
             options_.bag.c_str(), static_cast<unsigned long>(pass + 1), shift.toSec());
  }
  ROS_INFO("bag_player: done with '%s': %lu messages published in %.2f s (%.2f s of bag time)%s", options_.bag.c_str(),
           static_cast<unsigned long>(progress.count),
           progress.count ? (ros::WallTime::now() - progress.wall_start).toSec() : 0.0,
           progress.count ? (progress.last - progress.first).toSec() : 0.0,
           gate_->active() ? (", held back " + std::to_string(gate_->waits()) + " times for " +
                              std::to_string(gate_->waitedSeconds()) + " s in all").c_str() : "");
  if (is_node_ && options_.exit_when_done) ros::requestShutdown();
}

}  // namespace viper
