#!/usr/bin/env bash
# The segmentation baseline's tables (README.md, docs/baselines.md: the paper's Tables 1 and 2): the
# world captured in each condition on one route of the city's test region (the region of generate's
# small preset that training never visits: scripts/segmentation_plan.py trains in its train region),
# labelled from the world's oracle of the same run, and replayed per network through the ground
# truth, segmentation_baseline and evaluate (launch/benchmark_segmentation.launch); then
# scripts/segmentation_tables.py writes OUT/tables.md from evaluate's reports.
# Networks: models/segmentation_all.onnx (trained on every condition) and
# models/segmentation_day_sunset.onnx (day and sunset only).
# Usage: source devel/setup.bash; scripts/measure_segmentation.sh [--out build/segmentation_tables]
#          [--frames 200] [--fps 5] [--width 256] [--height 144] [--seed 11] [--rate 1.0]
#          [--conditions "day sunset rain snow night"] [--models "all day_sunset"]
# Exit 1 if a run failed or scored fewer frames than were captured.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out="$here/build/segmentation_tables" frames=200 fps=5 width=256 height=144 seed=11 rate=1.0
conditions="day sunset rain snow night" models="all day_sunset"
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2 ;; --frames) frames=$2 ;; --fps) fps=$2 ;; --width) width=$2 ;; --height) height=$2 ;;
    --seed) seed=$2 ;; --rate) rate=$2 ;; --conditions) conditions=$2 ;; --models) models=$2 ;;
    *) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
  shift 2
done
export ROS_HOME="${ROS_HOME:-$here/build/ros_home}"
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_ros_env measure_segmentation "$here/devel"
viper_bin_dir measure_segmentation "" capture world make_label_table
mkdir -p "$out"
# The test region of generate's small preset (city seed 1, 20 x 6 intersections; train is 0,0,5,5).
region=14,0,19,5
# Cityscapes ignores ground-truth instances under 100 px of its 2048x1024 frames; the same share of
# these frames (256x144: 2 px).
eval_min_px=$(( (100 * width * height + 1048576) / 2097152 ))
[ "$eval_min_px" -ge 1 ] || eval_min_px=1
echo "world ${width}x${height}, $frames frames at $fps fps, city seed 1 region $region, seed $seed, ego drive;" \
     "evaluate ignores instances under $eval_min_px px; replay rate $rate"

status=0
for condition in $conditions; do
  capture="$out/$condition.vcap" oracle="$out/$condition.oracle" labels="$out/${condition}_labels.yaml"
  echo "== $condition: capture"
  "$bin/capture" --output "$capture" --profile "$here/config/profiles/world.yaml" --condition "$condition" \
    --fps "$fps" -- "$bin/world" --condition "$condition" --ego drive --seed "$seed" --frames "$frames" \
    --width "$width" --height "$height" --fps "$fps" --city-seed 1 --region "$region" --oracle "$oracle" \
    > "$out/${condition}_capture.log" 2>&1
  "$bin/make_label_table" "$capture" "$oracle" "$labels" >> "$out/${condition}_capture.log" 2>&1
  for model in $models; do
    report="$out/${condition}_$model"
    echo "== $condition: segmentation_$model"
    rm -rf "$report"
    if ! timeout 1800 roslaunch viper benchmark_segmentation.launch capture:="$capture" label_table:="$labels" \
        report_dir:="$report" model:="$here/models/segmentation_$model.onnx" rate:="$rate" \
        eval_min_instance_px:="$eval_min_px" > "$report.log" 2>&1 || [ ! -f "$report/semantic_iou.csv" ]; then
      echo "measure_segmentation: run $condition/$model failed (log: $report.log)" >&2
      status=1
    fi
  done
  rm -f "$capture" "$oracle"
done
"$py" "$here/scripts/segmentation_tables.py" --frames "$frames" --models "$models" "$out" | tee "$out/tables.md" || status=1
exit $status
