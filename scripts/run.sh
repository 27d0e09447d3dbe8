#!/usr/bin/env bash
# The main job: capture the built-in world (or the test scene) through the interceptor, bridge the
# capture into ROS and record a raw bag, generate the ground truth of every frame (VIPER's layout and
# a ground-truth bag), draw a contact sheet of it, and print a summary and the command that shows it.
# Usage: scripts/run.sh [--program world|test_scene (world)] [--frames N (30)] [--width W (640)]
#                       [--height H (480)] [--condition day|sunset|rain|snow|night (day)] [--out DIR (build/run)]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
program=world; frames=30; width=640; height=480; condition=day; out="$here/build/run"
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '2,6' "run.sh: unknown option '{}' (see --help)" --program=program --frames=frames \
  --width=width --height=height --condition=condition --out=out -- "$@"
case "$program" in
  world) program_args=(--condition "$condition") ;;
  test_scene) program_args=() ;;
  *) echo "run.sh: --program must be world or test_scene, not '$program'" >&2; exit 2 ;;
esac
# This checkout's build, whatever workspace the shell has sourced.
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_ros_env run.sh "$here/devel"
viper_bin_dir run.sh "" capture "$program" generate capture_sheet capture_info capture_bridge
mkdir -p "$out"
capture="$out/$program.vcap"; oracle="$out/$program.oracle"; bag="$out/${program}_raw.bag"
case "$program" in
  world) labels="$here/config/labels/world_labels.yaml" ;;
  test_scene) labels="$here/config/labels/test_scene_labels.yaml" ;;
esac

echo "== capturing $frames frames of the $program at ${width}x${height} ($condition) -> $capture"
# Both programs advance 1/15 s per frame: --fps 15 stamps the frames with that time.
"$bin/capture" --output "$capture" --profile "$here/config/profiles/$program.yaml" --condition "$condition" --fps 15 \
  -- "$bin/$program" --frames "$frames" --width "$width" --height "$height" --oracle "$oracle" "${program_args[@]}"

echo "== bridging it into ROS and recording the raw topics -> $bag"
bash "$here/scripts/make_test_bag.sh" --capture "$capture" --output "$bag"

echo "== ground truth of every frame (generate, lockstep) -> $out/dataset"
"$bin/generate" --input "$capture" --labels "$labels" --out "$out/dataset" --force

sheet="$out/ground_truth.png"
last=$((frames - 2)); mid=$((frames / 2))  # the flow of a frame needs the next one
echo "== contact sheet of frames 0, $mid, $last (color, semantic, instances, depth, flow) -> $sheet"
"$bin/capture_sheet" "$capture" --frames "0,$mid,$last" --labels "$labels" --out "$sheet"

echo "== summary"
"$bin/capture_info" "$capture"
ros_tool rosbag info "$bag"
echo "ground truth: $out/dataset (VIPER's layout under train/, the ground-truth bag train/bag/001.bag,"
echo "              the marker train/001.done); contact sheet: $sheet"
echo "look at it:   source $here/devel/setup.bash && roslaunch viper view_bag.launch bag:=$out/dataset/train/bag/001.bag"
