#!/usr/bin/env bash
# Counts the frames the whole ground-truth pipeline delivers from a raw 1920x1080 bag played at its
# own rate (15 Hz): captures the world, records a raw bag (scripts/make_test_bag.sh), starts
# replay.launch's nodelets in one manager, plays the bag with rosbag play --clock, and counts the
# messages on every ground-truth output (scripts/count_topics.py). Exits 1 if any topic missed a frame.
#
# Usage: scripts/measure_pipeline.sh [--frames N (45)] [--width W (1920)] [--height H (1080)] [--no-flow]
# Needs a built workspace sourced first: source build/devel/setup.bash
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=45 width=1920 height=1080 flow=true
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --width) width="$2"; shift 2 ;;
    --height) height="$2"; shift 2 ;;
    --no-flow) flow=false; shift ;;
    *) echo "usage: $0 [--frames N] [--width W] [--height H] [--no-flow]" >&2; exit 2 ;;
  esac
done
command -v catkin_find >/dev/null || { echo "measure_pipeline: source <build>/devel/setup.bash first" >&2; exit 2; }
py=/usr/bin/python3
ros_tool() { local tool=$1; shift; "$py" "$(command -v "$tool")" "$@"; }
bin=$(dirname "$("$py" "$(command -v catkin_find)" --without-underlays --libexec viper | head -1)/x")

work=$(mktemp -d /tmp/viper_measure_pipeline.XXXXXX)
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

echo "measure_pipeline: capturing $frames frames of the world at ${width}x${height}"
"$bin/capture" --output "$work/world.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 \
  -- "$bin/world" --frames "$frames" --width "$width" --height "$height" >/dev/null
echo "measure_pipeline: captured (${SECONDS} s)"
bash "$here/scripts/make_test_bag.sh" --capture "$work/world.vcap" --output "$work/raw.bag"

echo "measure_pipeline: bag written (${SECONDS} s)"
port=$(( 20000 + RANDOM % 20000 ))
export ROS_MASTER_URI="http://localhost:$port" ROS_HOME="$work/ros_home"
"$py" "$(command -v roslaunch)" -p "$port" viper replay.launch label_table:="$here/config/labels/world_labels.yaml" flow:="$flow" \
  >"$work/launch.log" 2>&1 &
pids+=($!)
for _ in $(seq 150); do
  ros_tool rosnode list 2>/dev/null | grep -q ground_truth/odometry && break
  sleep 0.2
done

# Flow exists for every frame but one: forward flow of the last frame and backward flow of the first
# have no other frame.
topics=(/capture/draws /ground_truth/semantic /ground_truth/instance_ids /ground_truth/objects
        /ground_truth/boxes /ground_truth/odom)
# The masks (1 byte/px) stand for the flow images (8 bytes/px, computed together): a Python counter
# cannot take 2 x 16 MB per frame at 15 Hz itself.
[ "$flow" = true ] && topics+=("/ground_truth/flow/forward_visible@$((frames - 1))" "/ground_truth/flow/backward_visible@$((frames - 1))")
"$py" "$here/scripts/count_topics.py" --expect "$frames" --timeout 20 "${topics[@]}" >"$work/counts.txt" 2>&1 &
counter=$!
for _ in $(seq 100); do grep -q subscribed "$work/counts.txt" && break; sleep 0.2; done
sleep 3  # let the subscriptions connect before the first message
echo "measure_pipeline: playing (${SECONDS} s)"
start=$(date +%s.%N)
ros_tool rosbag play --clock --quiet "$work/raw.bag"
end=$(date +%s.%N)
status=0
wait "$counter" || status=$?
echo "machine: $(nproc) cores; bag: $frames frames ${width}x${height}, $(du -h "$work/raw.bag" | cut -f1), played in $(echo "$end - $start" | bc) s"
grep -v subscribed "$work/counts.txt"
[ "$status" = 0 ] && echo "measure_pipeline: no frame dropped" || { echo "measure_pipeline: frames dropped" >&2; tail -20 "$work/launch.log" >&2; }
exit "$status"
