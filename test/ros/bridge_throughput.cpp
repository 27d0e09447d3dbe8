// Measures how many complete frames per second capture_bridge delivers to a subscriber in another
// process: a frame counts when its color, depth, both camera infos, draw ids, primitive ids and draw
// list (one stamp) have all arrived. Prints frames, seconds and frames/s, then exits.
//
// Usage (in the bridge's namespace): bridge_throughput _frames:=N [_idle_timeout_s:=5]
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>

#include <cstdio>
#include <map>

namespace {

std::map<ros::Time, int> parts;
int complete = 0;
ros::WallTime first_complete, last_complete, last_message;

void onHeader(const std_msgs::Header& h) {
  last_message = ros::WallTime::now();
  if (++parts[h.stamp] == 7) {
    if (complete++ == 0) first_complete = last_message;
    last_complete = last_message;
    parts.erase(h.stamp);
  }
}

void onImage(const sensor_msgs::ImageConstPtr& m) { onHeader(m->header); }
void onInfo(const sensor_msgs::CameraInfoConstPtr& m) { onHeader(m->header); }
void onDraws(const viper::DrawListConstPtr& m) { onHeader(m->header); }

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "bridge_throughput");
  ros::NodeHandle nh, pnh("~");
  int frames = 0;
  double idle_timeout_s = 5.0;
  pnh.param("frames", frames, 0);
  pnh.param("idle_timeout_s", idle_timeout_s, idle_timeout_s);
  const uint32_t q = 10;
  std::vector<ros::Subscriber> subs = {
      nh.subscribe("color/image_raw", q, onImage),     nh.subscribe("depth/image_raw", q, onImage),
      nh.subscribe("draw_ids", q, onImage),            nh.subscribe("primitive_ids", q, onImage),
      nh.subscribe("color/camera_info", q, onInfo),    nh.subscribe("depth/camera_info", q, onInfo),
      nh.subscribe("draws", q, onDraws),
  };
  last_message = ros::WallTime::now();
  while (ros::ok() && (frames <= 0 || complete < frames)) {
    ros::spinOnce();
    // The idle timeout starts only once frames flow (the bridge may wait for subscribers first).
    if (complete > 0 && (ros::WallTime::now() - last_message).toSec() > idle_timeout_s) break;
    ros::WallDuration(0.001).sleep();
  }
  const double seconds = (last_complete - first_complete).toSec();
  std::printf("complete frames: %d, incomplete stamps: %zu, first to last: %.3f s, %.2f frames/s\n", complete,
              parts.size(), seconds, complete > 1 ? (complete - 1) / seconds : 0.0);
  return complete > 0 ? 0 : 1;
}
