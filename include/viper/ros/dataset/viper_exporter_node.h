// viper_exporter: writes live ground-truth topics into VIPER's release layout (img, cls, inst, flow,
// flowbw, bb, camera), frame by frame, as the ground-truth nodes publish them. Node, nodelet
// (viper/viper_exporter) and `export_viper --live` run this class. docs/viper_layout.md.
#pragma once

#include "viper/ros/dataset/export_roles.h"
#include "viper/ros/dataset/viper_exporter.h"

#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace viper {

/// What a live export writes and listens to.
struct LiveExportConfig {
  ViperExportOptions exporter;  ///< root, split, seq, formats, palette, camera source, ...
  std::vector<ExportRole> roles = defaultExportRoles();  ///< topic "" = role off
  std::string frames_from;      ///< reference topic; "" = the color role's
  std::string camera = "draws"; ///< draws, odom or none ("auto" means draws live)
  uint64_t first_frame = 0;     ///< number of the first frame
};

/// Frame n is the n-th header stamp of the reference topic (plus first_frame); messages of a stamp
/// the reference has not brought yet wait for it (up to 64 stamps). A frame is completed once the
/// reference is 30 frames ahead of it, or at finish().
class ViperExporterNode {
 public:
  /// The node and nodelet: settings from private parameters (docs/viper_layout.md#viper_exporter),
  /// topics relative to `nh` (remappable).
  ViperExporterNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// export_viper --live: settings from its command line, topics as given.
  ViperExporterNode(const ros::NodeHandle& nh, const LiveExportConfig& config);
  /// finish() if it has not run.
  ~ViperExporterNode();

  /// Reads and checks the settings (the node's parameters), creates the exporter, subscribes and
  /// offers ~finish. False after a ROS_FATAL naming what to fix.
  bool start();
  /// The node shell's start: `is_node` (a process of its own, as export_viper --live is too) ends
  /// the process when a file cannot be written (a full disk), with finish()'s exit code 2; a
  /// nodelet stops exporting and stays loaded.
  bool start(bool is_node);
  /// The node's exit status: 2 once a file could not be written, else 0 (skipped messages are
  /// reported in the log and by ~finish, not by the status of a node).
  int exitCode() const;
  /// Completes every frame, closes the camera file and stops listening. Returns the exit code of
  /// export_viper: 0 everything exported, 1 messages skipped or dropped, 2 a file could not be
  /// written. Later calls return the same.
  int finish();
  /// The node's end: finish().
  void stop() { finish(); }

  uint64_t framesNumbered() const;
  /// Whether every topic listened to has a publisher.
  bool inputsConnected() const;
  /// Messages handed to the exporter or still waiting for their stamp, over every topic.
  uint64_t messagesReceived() const;
  /// The summary line (counts per modality, skipped and dropped messages).
  std::string summary() const;

 private:
  bool readParameters();
  template <typename M>
  void subscribe(const ExportRole& role);
  void onMessage(const std::string& topic, const ros::Time& stamp, const ExportDispatch& dispatch);
  void run(const std::string& topic, const ros::Time& stamp, uint64_t frame, const ExportDispatch& dispatch);
  void flush(uint64_t frame);
  void fail(const std::string& why);  // a file could not be written
  bool onFinish(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  ros::NodeHandle nh_, private_nh_;
  bool from_parameters_;
  LiveExportConfig config_;
  std::unique_ptr<ViperExporter> exporter_;
  std::string reference_;
  std::vector<ros::Subscriber> subs_;
  ros::ServiceServer finish_srv_;
  mutable std::mutex mutex_;
  std::map<ros::Time, uint64_t> frame_of_;
  std::map<ros::Time, std::vector<std::pair<std::string, ExportDispatch>>> waiting_;
  uint64_t next_frame_ = 0, newest_ = 0;
  size_t dropped_ = 0;
  uint64_t received_ = 0;
  bool failed_ = false, finished_ = false;
  bool own_process_ = false;  // a write failure ends the process (ros::requestShutdown)
  int exit_code_ = 0;
};

}  // namespace viper
