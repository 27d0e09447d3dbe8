#include "viper/ros/ground_truth/boxes.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/ground_truth/instances.h"

namespace viper {

Boxes::Boxes(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), private_nh_(pnh) {}

bool Boxes::start() {
  classes_ = loadClassTableParam(private_nh_);
  if (!classes_) return false;
  private_nh_.param<std::string>("map_frame", map_frame_, "map");
  int queue_size = 10;
  private_nh_.param("queue_size", queue_size, 10);
  if (queue_size < 1) {
    ROS_ERROR("%s: ~queue_size must be >= 1 (got %d); using 10", private_nh_.getNamespace().c_str(), queue_size);
    queue_size = 10;
  }
  boxes_pub_ = nh_.advertise<Box3DArray>("boxes", queue_size);
  boxes_optical_pub_ = nh_.advertise<Box3DArray>("boxes_optical", queue_size);
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("box_markers", queue_size);
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Boxes::onMeshStore, this);
  objects_sub_.subscribe(nh_, "objects", queue_size);
  draws_sub_.subscribe(nh_, "draws", queue_size);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(queue_size), objects_sub_, draws_sub_);
  sync_->registerCallback(&Boxes::onFrame, this);
  return true;
}

void Boxes::onMeshStore(const MeshStore::ConstPtr& store) {
  std::vector<std::string> problems;
  std::vector<MeshRecord> meshes = fromMeshStoreMsg(*store, problems);
  for (const std::string& p : problems) ROS_ERROR_THROTTLE(5, "%s: %s", mesh_store_sub_.getTopic().c_str(), p.c_str());
  std::lock_guard<std::mutex> lock(mutex_);
  meshes_.add(meshes);
}

void Boxes::onFrame(const ObjectArray::ConstPtr& objects, const DrawList::ConstPtr& draws) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string& topic = objects_sub_.getTopic();
  CaptureFrame frame;
  fromDrawListMsg(*draws, frame);
  const double t = draws->header.stamp.toSec();

  std::optional<Eigen::Isometry3d> optical_from_map;
  if (auto camera = chooseFrameCamera(frame)) {
    if (camera->view.allFinite()) optical_from_map = opticalFromWorld(camera->view);
  }
  if (!optical_from_map)
    ROS_WARN_THROTTLE(5, "%s: frame %lu has no usable view matrix; boxes_optical not published", topic.c_str(),
                      static_cast<unsigned long>(draws->frame_number));

  Box3DArray in_map, in_optical;
  in_map.header = draws->header;
  in_map.header.frame_id = map_frame_;
  in_optical.header = draws->header;
  std::map<int32_t, LastSeen> seen;
  for (const Object& o : objects->objects) {
    if (o.track_id <= 0 || o.draws.empty()) continue;
    if (o.draws.front() >= frame.draws.size()) {
      ROS_ERROR_THROTTLE(5, "%s: track %d names draw %u but the frame has %zu draws; object skipped", topic.c_str(),
                         o.track_id, o.draws.front(), frame.draws.size());
      continue;
    }
    FrameObject fo;
    fo.draws = o.draws;
    fo.class_id = o.class_id;
    fo.is_thing = true;
    fo.world = frame.draws[o.draws.front()].world;
    BoxStatus status;
    const OrientedBox box = objectBox(frame, fo, meshes_, &status);
    if (status != BoxStatus::kOk) {
      ROS_WARN_THROTTLE(5, "%s: track %d (%s): %s; no box", topic.c_str(), o.track_id, o.class_name.c_str(),
                        status == BoxStatus::kMissingMesh ? "none of its meshes has arrived"
                        : status == BoxStatus::kSingularMatrix ? "its world matrix is singular or not finite"
                                                               : "it has no vertices");
      continue;
    }
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    auto it = last_seen_.find(o.track_id);
    if (it != last_seen_.end() && t > it->second.time_s) velocity = (box.center - it->second.center) / (t - it->second.time_s);
    seen[o.track_id] = {box.center, t};
    in_map.boxes.push_back(toBox3DMsg(box, o.track_id, o.class_id, *classes_, velocity));
    if (optical_from_map)
      in_optical.boxes.push_back(
          toBox3DMsg(box.transformed(*optical_from_map), o.track_id, o.class_id, *classes_, optical_from_map->linear() * velocity));
  }
  last_seen_.swap(seen);
  boxes_pub_.publish(in_map);
  if (optical_from_map) boxes_optical_pub_.publish(in_optical);
  if (markers_pub_.getNumSubscribers() > 0) markers_pub_.publish(boxMarkers(in_map, *classes_));
}

}  // namespace viper
