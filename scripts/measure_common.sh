# Sourced by scripts/measure_pipeline.sh and measure_evaluate.sh: Debian's python for the ROS tools
# (ros_tool), the sourced workspace's executables ($bin), a work folder ($work) removed on exit
# together with every background process listed in $pids.
# Usage: source "$here/scripts/measure_common.sh" NAME
command -v catkin_find >/dev/null || { echo "$1: source <build>/devel/setup.bash first" >&2; exit 2; }
py=/usr/bin/python3
ros_tool() { local tool=$1; shift; "$py" "$(command -v "$tool")" "$@"; }
bin=$(dirname "$("$py" "$(command -v catkin_find)" --without-underlays --libexec viper | head -1)/x")

work=$(mktemp -d "/tmp/viper_$1.XXXXXX")
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

# rosbag play in the background, kept alive after the bag's end (--keep-alive): a player that exits
# drops what its outgoing queues still hold, i.e. the large images it could not send yet, and that
# would count as frames the subscribers lost. stdin is a FIFO this shell keeps open (rosbag play
# reads keys from it; /dev/null would stall it). Node name /bag_player; stop it with stop_bag.
play_bag() {
  mkfifo "$work/play.in"
  ros_tool rosbag play --quiet --keep-alive --delay=2 "$@" __name:=bag_player <"$work/play.in" >"$work/play.log" 2>&1 &
  pids+=($!)
  exec 9>"$work/play.in"
}
stop_bag() { ros_tool rosnode kill /bag_player >/dev/null 2>&1 || true; }
