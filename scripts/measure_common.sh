# Sourced by scripts/measure_pipeline.sh, measure_evaluate.sh, measure_kernels.sh and
# soak_pipeline.sh: the ROS environment, Debian's python for the ROS tools ($py, ros_tool) and the
# package's executables ($bin: every EXECUTABLE named, checked), all as scripts/package_binaries.sh
# finds them (the sourced workspace, else this checkout's devel space); a work folder ($work)
# removed on exit together with every background process listed in $pids.
# Usage: source "$here/scripts/measure_common.sh" NAME EXECUTABLE...
# shellcheck source=package_binaries.sh
source "$(dirname "${BASH_SOURCE[0]}")/package_binaries.sh"
viper_ros_env "$1"
viper_bin_dir "$1" "" "${@:2}"

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

# replay.launch on a master of its own (port chosen at random) with the arguments given, then the
# output_counter nodelet in its manager (its ~report_file is $work/counts.txt; COUNTER_ARGS adds
# parameters), and $manager set to the manager's pid. Logs: $work/launch.log, $work/counter.log.
# Usage: start_pipeline [replay.launch ARG:=VALUE ...]
start_pipeline() {
  local port=$(( 20000 + RANDOM % 20000 ))
  export ROS_MASTER_URI="http://localhost:$port" ROS_HOME="$work/ros_home"
  "$py" "$(command -v roslaunch)" -p "$port" viper replay.launch "$@" >"$work/launch.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 150); do
    ros_tool rosnode list 2>/dev/null | grep -q ground_truth/odometry && break
    sleep 0.2
  done
  # shellcheck disable=SC2086
  rosrun nodelet nodelet load viper/output_counter /viper_manager __name:=output_counter __ns:=ground_truth \
    _report_file:="$work/counts.txt" _idle_s:=5 ${COUNTER_ARGS:-} >"$work/counter.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do ros_tool rosnode list 2>/dev/null | grep -q /ground_truth/output_counter && break; sleep 0.2; done
  manager=$(ros_tool rosnode info /viper_manager 2>/dev/null | sed -n 's/^Pid: //p')
}
