#!/usr/bin/env bash
# bench_bag_writer on real ground truth: FRAMES frames of the world at WIDTH x HEIGHT under capture,
# labelled from its oracle and generated into a ground-truth bag (generate --outputs bag), whose
# messages rosbag and BagFileWriter then write again (bench/bench_bag_writer.cpp); then
# bench_bag_reader reads that bag and capture_to_bag's raw bag of the capture with rosbag::View and
# with BagFileReader (bench/bench_bag_reader.cpp).
# Usage: source devel/setup.bash; scripts/bench_bag_writer.sh [--frames 10] [--width 1920] [--height 1080]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=10 width=1920 height=1080
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames=$2 ;; --width) width=$2 ;; --height) height=$2 ;;
    *) sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
  shift 2
done
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir bench_bag_writer "" capture world make_label_table generate capture_to_bag bench_bag_writer bench_bag_reader
work=$(mktemp -d /tmp/viper_bench_bag_writer.XXXXXX)
trap 'rm -rf "$work"' EXIT
"$bin/capture" --output "$work/w.vcap" --profile "$here/config/profiles/world.yaml" --condition day --fps 15 -- \
  "$bin/world" --condition day --ego drive --seed 3 --frames "$frames" --width "$width" --height "$height" --fps 15 \
  --oracle "$work/w.oracle" > "$work/capture.log" 2>&1
"$bin/make_label_table" "$work/w.vcap" "$work/w.oracle" "$work/labels.yaml" > /dev/null
"$bin/generate" --input "$work/w.vcap" --labels "$work/labels.yaml" --out "$work/D" --outputs bag > "$work/generate.log" 2>&1
VIPER_BENCH_BAG="$work/D/train/bag/001.bag" "$bin/bench_bag_writer"
# And reading (bench/bench_bag_reader.cpp: rosbag::View against BagFileReader, what bag_player uses):
# that ground-truth bag, and the raw bag capture_to_bag makes of the same capture.
"$bin/capture_to_bag" --output "$work/raw.bag" "$work/w.vcap" > /dev/null
for bag in "$work/D/train/bag/001.bag" "$work/raw.bag"; do
  echo "bench_bag_reader: $(basename "$bag") ($(du -h "$bag" | cut -f1), $frames frames)"
  VIPER_BENCH_BAG="$bag" "$bin/bench_bag_reader"
done
