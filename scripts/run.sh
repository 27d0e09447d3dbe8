#!/usr/bin/env bash
# The main job: capture the test scene through the interceptor, bridge the capture into ROS,
# record a raw bag, and print a summary of what was captured.
# Usage: scripts/run.sh [--frames N] [--width W] [--height H] [--out DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=30; width=640; height=480; out="$here/build/run"
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --width) width="$2"; shift 2 ;;
    --height) height="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,4p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
# shellcheck disable=SC1091
source "$here/build/devel/setup.bash"
export ROS_HOME="${ROS_HOME:-$here/build/ros_home}"
mkdir -p "$out"
capture="$out/test_scene.vcap"; bag="$out/test_scene_raw.bag"

echo "== capturing $frames frames of the test scene at ${width}x${height} -> $capture"
rosrun viper capture --output "$capture" --profile "$here/config/profiles/test_scene.yaml" \
  --condition day -- "$(catkin_find viper test_scene --first-only)" \
  --frames "$frames" --width "$width" --height "$height"

echo "== bridging it into ROS and recording the raw topics -> $bag"
bash "$here/scripts/record_raw_bag.sh" "$capture" "$bag"

echo "== summary"
rosrun viper capture_info "$capture"
/usr/bin/python3 "$(command -v rosbag)" info "$bag"
