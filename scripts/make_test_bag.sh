#!/usr/bin/env bash
# Captures the test scene, replays the capture with capture_bridge as fast as the recorder takes it
# (rate 0, waiting for the recorder's subscriptions) and records the raw topics into a bag.
#
# Usage: scripts/make_test_bag.sh [--frames N (20)] [--output BAG (bags/test_scene_raw.bag)]
#                                 [--capture FILE.vcap (use this capture instead of capturing)]
# Needs a built workspace: the sourced one (source devel/setup.bash), else this checkout's devel space.
# Runs its own roscore on a free port, so it neither needs nor disturbs a running one.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=20
bag="$here/bags/test_scene_raw.bag"
capture=""
# options.sh and package_binaries.sh lie beside this script, in the source tree and where it is
# installed (lib/viper: cmake/bridge.cmake).
# shellcheck source=options.sh
source "$(dirname "$0")/options.sh"
viper_options '' "usage: $0 [--frames N] [--output BAG] [--capture FILE.vcap]" --frames=frames --output=bag \
  --capture=capture -- "$@"
# shellcheck source=package_binaries.sh
source "$(dirname "$0")/package_binaries.sh"
viper_ros_env make_test_bag
# The package's executables (what `rosrun viper NAME` runs, without rosrun's prompt when several
# build folders inside the source tree hold one).
viper_bin_dir make_test_bag "" capture_bridge $([ -n "$capture" ] || echo capture test_scene)

work=$(mktemp -d /tmp/viper_make_test_bag.XXXXXX)
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

if [ -z "$capture" ]; then
  capture="$work/test_scene.vcap"
  echo "make_test_bag: capturing $frames frames of the test scene"
  "$bin/capture" --output "$capture" --profile "$here/config/profiles/test_scene.yaml" --fps 15 \
    -- "$bin/test_scene" --frames "$frames"
fi

port=$(( 20000 + RANDOM % 20000 ))
export ROS_MASTER_URI="http://localhost:$port" ROS_HOME="$work/ros_home"
roscore -p "$port" >"$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
  ros_tool rosparam get /run_id >/dev/null 2>&1 && break
  sleep 0.2
done
ros_tool rosparam get /run_id >/dev/null 2>&1 || { echo "make_test_bag: roscore did not start" >&2; exit 1; }

topics=(/capture/color/image_raw /capture/color/camera_info /capture/depth/image_raw /capture/depth/camera_info
        /capture/draw_ids /capture/primitive_ids /capture/draws /capture/mesh_store)
mkdir -p "$(dirname "$bag")"
rm -f "$bag" "$bag.active"
ros_tool rosbag record --lz4 -O "$bag" __name:=raw_recorder "${topics[@]}" >"$work/rosbag.log" 2>&1 &
pids+=($!)

# The bridge starts publishing only once the recorder subscribes to every topic, and exits after
# the last frame (~exit_when_done), so no frame is published before or after recording.
"$bin/capture_bridge" __ns:=capture _file:="$capture" _rate:=0 _wait_for_subscribers:=true \
  _queue_size:=100 _exit_when_done:=true 2>&1 | tee "$work/bridge.log"
published=$(sed -n 's/.*: \([0-9]*\) frames published.*/\1/p' "$work/bridge.log" | tail -1)

ros_tool rosnode kill /raw_recorder >/dev/null
for _ in $(seq 100); do
  [ -f "$bag" ] && [ ! -f "$bag.active" ] && break
  sleep 0.2
done
[ -f "$bag" ] || { echo "make_test_bag: rosbag did not write $bag" >&2; cat "$work/rosbag.log" >&2; exit 1; }

# Every published frame must be in the bag, on every per-frame topic.
counts=$(ros_tool rosbag info --yaml --key=topics "$bag")
for t in "${topics[@]}"; do
  [ "$t" = /capture/mesh_store ] && continue
  n=$(printf '%s\n' "$counts" | grep -A3 "topic: $t\$" | sed -n 's/.*messages: *\([0-9]*\).*/\1/p')
  if [ "${n:-0}" != "${published:-x}" ]; then
    echo "make_test_bag: $t has ${n:-0} messages, the bridge published ${published:-?} frames" >&2
    exit 1
  fi
done
echo "make_test_bag: wrote $bag ($published frames, $(du -h "$bag" | cut -f1))"
