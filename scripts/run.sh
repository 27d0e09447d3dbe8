#!/usr/bin/env bash
# The main job: capture the test scene through the interceptor, bridge the capture into ROS,
# record a raw bag, and print a summary of what was captured.
# Usage: scripts/run.sh [--frames N (30)] [--width W (640)] [--height H (480)] [--condition TAG (day)]
#                       [--out DIR (build/run)]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=30; width=640; height=480; condition=day; out="$here/build/run"
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --width) width="$2"; shift 2 ;;
    --height) height="$2"; shift 2 ;;
    --condition) condition="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,5p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
bin="$here/build/devel/lib/viper"
[ -x "$bin/capture" ] || { echo "run.sh: nothing built in $here/build: run scripts/setup.sh first" >&2; exit 2; }
# shellcheck disable=SC1091
set +u  # ROS env hooks read unset variables
source "$here/build/devel/setup.bash"
set -u
mkdir -p "$out"
capture="$out/test_scene.vcap"; oracle="$out/test_scene.oracle"; bag="$out/test_scene_raw.bag"

echo "== capturing $frames frames of the test scene at ${width}x${height} ($condition) -> $capture"
"$bin/capture" --output "$capture" --profile "$here/config/profiles/test_scene.yaml" --condition "$condition" --fps 15 \
  -- "$bin/test_scene" --frames "$frames" --width "$width" --height "$height" --oracle "$oracle"

echo "== bridging it into ROS and recording the raw topics -> $bag"
bash "$here/scripts/make_test_bag.sh" --capture "$capture" --output "$bag"

echo "== summary"
"$bin/capture_info" "$capture"
/usr/bin/python3 "$(command -v rosbag)" info "$bag"
