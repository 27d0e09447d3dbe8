#!/usr/bin/env bash
# The reference baseline tables of README.md: captures the world in each condition (same route,
# ego driving), scores the baselines on each capture with evaluate (launch/benchmark_baselines.launch)
# and writes the tables over the conditions (scripts/baseline_tables.py) to OUT/tables.md.
#   run A: flow_baseline DIS + opencv_apps lk_flow (sparse) + vo_baseline
#   run B: flow_baseline Farneback + opencv_apps fback_flow (sparse)
# Usage: scripts/measure_baselines.sh [--out DIR (build/baselines)] [--frames 450] [--width 640]
#   [--height 360] [--rate 0.5] [--segments "[10, 20, 40, 80]"] [--conditions "day sunset rain snow night"]
# Takes ~15 minutes with the defaults on 2 cores. Exit 1 if a run failed or lost frames.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out="$here/build/baselines" frames=450 width=640 height=360 rate=0.5
segments="[10, 20, 40, 80]" conditions="day sunset rain snow night"
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2 ;; --frames) frames=$2 ;; --width) width=$2 ;; --height) height=$2 ;;
    --rate) rate=$2 ;; --segments) segments=$2 ;; --conditions) conditions=$2 ;;
    *) echo "measure_baselines: unknown option $1 (see the header of $0)" >&2; exit 2 ;;
  esac
  shift 2 || { echo "measure_baselines: $1 needs a value" >&2; exit 2; }
done
export ROS_HOME="${ROS_HOME:-$here/build/ros_home}"
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_ros_env measure_baselines "$here/devel"
viper_bin_dir measure_baselines "" capture world  # what capture_world.sh runs
mkdir -p "$out"
echo "machine: $(nproc) cores, $(free -g | awk '/Mem/ {print $2}') GiB; world ${width}x${height}, $frames frames at 15 fps, replay rate $rate"

status=0
for condition in $conditions; do
  capture="$out/$condition.vcap"
  echo "== $condition: capture"
  bash "$here/scripts/capture_world.sh" "$capture" --condition "$condition" --ego drive --frames "$frames" \
    --width "$width" --height "$height" > "$out/${condition}_capture.log" 2>&1
  for run in "dis lk_flow true" "farneback fback_flow false"; do
    set -- $run
    report="$out/${condition}_$1"
    echo "== $condition: $1 + $2$([ "$3" = true ] && echo " + vo_baseline")"
    rm -rf "$report"
    if ! timeout 1800 roslaunch viper benchmark_baselines.launch capture:="$capture" report_dir:="$report" \
        rate:="$rate" flow_method:="$1" sparse:="$2" vo:="$3" odometry_segment_lengths_m:="$segments" \
        > "$report.log" 2>&1 || [ ! -f "$report/flow.csv" ]; then
      echo "measure_baselines: run $condition/$1 failed (log: $report.log)" >&2
      status=1
    fi
  done
  rm -f "$capture"
done
"$py" "$here/scripts/baseline_tables.py" --frames "$frames" "$out" | tee "$out/tables.md" || status=1
exit $status
